// SPDX-License-Identifier: Apache-2.0
// The camera's timing against the projectors' flips, measured from the pattern sequence itself (no clock, no
// ground truth): a camera frame whose exposure straddles a flip, or a driver that hands out a frame queued before
// it, mixes the previous pattern's light into the next one's image. Gray-code pairs then lose bits and the
// phase-shifted sinusoids, each mixed with the shift before it, decode with a constant phase offset: content lands
// off by a share of the sinusoid's period, and nothing in the fit's residuals shows it (docs/calibration.md,
// "Camera timing"). Internal to mogao_autocal: calibrate() measures it before any other pattern.
#pragma once

#include <vector>

#include "appliance/autocal/autocal.h"

namespace mogao::autocal {

struct FrameStraddle {
    double share =
        0.0;         // of the previous pattern's light in the first frame after a change (0: none, 1: a stale frame)
    int pixels = 0;  // camera pixels it was measured on (0: the camera saw no projector light; share 0)
};

// Shows every projector white twice (the first frame may hold whatever was shown before), then black twice, each a
// single camera frame, two pictures the calibration shows anyway (the captured-images route's `white` and `black`):
// the share is the median, over the camera pixels white lights by more than `min_contrast`, of (first black - second
// black) / (white - second black). A straddled first black holds share x white + (1 - share) x black; noise averages
// out over the pixels (the median of ~1e5 ratios), and where overlapping projectors clip the camera (a minority of
// the pixels) the median does not follow them. Four captures, added to `captures`.
[[nodiscard]] FrameStraddle measure_frame_straddle(PatternSource& source, const std::vector<ImageSize>& sizes,
                                                   double min_contrast, int& captures);

}  // namespace mogao::autocal
