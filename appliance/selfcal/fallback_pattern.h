// SPDX-License-Identifier: Apache-2.0
// The content-independent fallback of self-recalibration (docs/calibration.md,
// "Self-recalibration"): when the tour shows too little texture, and only if configured, the
// display adds a low-amplitude pattern to the content over two refreshes, +a P then -a P (a
// complementary pair: the eye integrates the two to the content alone, as in imperceptible
// structured light, Raskar et al. 1998 "The office of the future"; Cotting et al. 2004), and the
// monitor works on the difference of the two camera frames, which holds 2a P as the screen shows
// it and none of the content.
//
// P is a sparse random-dot pattern in content coordinates: one dot per cell of a jittered grid
// (blue-noise-like spacing, no repeated structure for the feature matcher to confuse), each dot a
// disc of random radius and strength in [0.5, 1]; 0 elsewhere. Its size is the content frame's
// (the display scales it to its own content size like the content).
#pragma once

#include <cstdint>

#include <opencv2/core.hpp>

namespace mogao::selfcal {

struct PatternOptions {
    bool enabled = false;  // off by default: without it a textureless scene only waits
    // a: added to and taken from the linear content (fraction of full white); 0.02 is about 4
    // 8-bit codes at the plain content's 0.3 grey after the projectors' gamma 2.2 response. (0, 0.2].
    double amplitude = 0.02;
    int cell_px = 24;       // dot spacing in content pixels (of a 960-pixel-wide frame), >= 6
    double recheck_s = 10;  // pattern mode lasts this long before the content alone is tried again, > 0
    std::uint64_t seed = 1;
};

// The unit pattern P (values in [0, 1]) for a content frame of `size`. Throws
// std::invalid_argument for a bad size or options.
[[nodiscard]] cv::Mat1f fallback_pattern(cv::Size size, const PatternOptions& options);

// Throws std::invalid_argument naming the bad field and its limit.
void check_pattern_options(const PatternOptions& options);

}  // namespace mogao::selfcal
