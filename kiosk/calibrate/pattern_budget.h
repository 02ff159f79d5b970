// SPDX-License-Identifier: Apache-2.0
// How many images the calibration captures and how long the capture takes on site: the figure the
// progress line's estimate starts from, and what docs/on-site-calibration.md tabulates.
//
// Count (an upper bound: the Gray code stops at the first bit the camera cannot resolve,
// appliance/autocal/gray_code.h): identification 2 + N (all black, all white, then each output white alone,
// connector_identity.h); geometry 4 + F * (2 + 2 N + sum_k (2 + 2 * (bits(width_k) + bits(height_k)) + 2 * S)) (the
// camera timing's white, white, black, black, appliance/autocal/camera_timing.h; black and white of all, each
// projector white and grey alone for the lit edges, per projector white and black, each Gray bit and its inverse
// per axis, S phase shifts per axis; bits(n) = gray_code_bits, at most max_gray_bits; F
// frames_per_pattern); colour 5 + N + N * 3 * ((ramp_steps - 1) + low) + dark_frames with raw frames (the N: each
// projector's white for the screen's bounce), low = 2 + the ramp levels in (0, 1/4] other than 1/32 and 1/16
// (appliance/autocal/colour_calibration.h, step 1's low end); with `lossy_frames` (a Motion-JPEG camera: unknown
// before its first frame, so the on-site job counts raw) each of those images is at least dither_frames images
// (full_level_frames at the full level); self-check F' * (2 + 3 N) (black and each projector white and grey alone
// for the frame, black, then each projector's marks; F' its frames, appliance/autocal/self_check.h). Time per
// image = settle + (drop_frames + 1) / camera fps + exposure (the flip itself is within one refresh, part of the
// settle).
#pragma once

#include "appliance/autocal/autocal.h"
#include "appliance/autocal/colour_calibration.h"
#include "appliance/autocal/self_check.h"

namespace mogao::calibrate {

struct PatternBudget {
    int identification = 0;
    int geometry = 0;  // at most
    int colour = 0;
    int self_check = 0;
    [[nodiscard]] int total() const { return identification + geometry + colour + self_check; }
};

[[nodiscard]] PatternBudget pattern_budget(const autocal::CalibrationPrior& prior, bool colour,
                                           const autocal::ColourOptions& colour_options,
                                           const autocal::AutocalOptions& options,
                                           const autocal::SelfCheckOptions& self_check = {}, bool lossy_frames = false);

// Seconds to capture one image: settle_ms / 1000 + (drop_frames + 1) / fps. fps > 0.
[[nodiscard]] double seconds_per_image(double fps, int settle_ms, int drop_frames);

}  // namespace mogao::calibrate
