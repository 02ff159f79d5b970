// SPDX-License-Identifier: Apache-2.0
// Frame-time target of a live session: how much to render next so a frame takes `target_seconds`.
//
// The knob is the frame's work w = resolution_scale^2 * spp (pixels traced times samples, relative
// to the full-size frame at 1 spp); render time is close to proportional to it. After each frame the
// controller moves w toward the work that would have met the target, as Equalizer's dynamic frame
// resize does (S. Eilemann et al., "Equalizer: A Scalable Parallel Rendering Framework", IEEE TVCG
// 15(3), 2009, sec. 5.3; Equalizer's DFR equaliser scales each axis by sqrt(target / measured)):
//     w' = w_used * clamp(target / measured, 1/max_step, max_step) ^ gain
// gain in (0, 1] damps the step (1 = jump to the prediction at once; the default 0.5 halves the
// log-error each frame, so a frame that took twice the target shrinks each axis by 2^(1/4)).
// measured = 0 (a frame too fast to time) counts as the largest step up. w is then clamped so that
// the scale stays in [min_scale, the request's own scale] with each side at least
// request_limits::kLinkImageSide.min pixels, and spp in [1, max_spp] (request_limits::kSpp).
// The scale is spent first: spp (= round(w / scale^2)) rises above 1 only at the request's full scale.
//
// Units: seconds. Errors: the constructor throws std::invalid_argument naming a bad field.
#pragma once

#include "common/view_request.h"

namespace mogao {

struct FrameTimeTarget {
    double target_seconds = 1.0 / 15.0;  // > 0
    double gain = 0.5;                   // (0, 1]
    double max_step = 4.0;               // >= 1: largest change of w in one frame (factor)
    double min_scale = 0.2;              // (0, 1]
    int max_spp = 16;                    // in request_limits::kSpp
};

struct FrameChoice {
    double resolution_scale = 1.0;
    int spp = 1;
    [[nodiscard]] double work() const { return resolution_scale * resolution_scale * spp; }
};

class FrameTimeController {
public:
    explicit FrameTimeController(FrameTimeTarget target);

    // Scale and spp for the next frame of `request` (its size and resolution_scale bound the scale).
    // The first call, before any observe(), returns the request's own scale and spp (clamped).
    [[nodiscard]] FrameChoice choose(const ViewRequest& request) const;
    // The frame rendered with `used` took `seconds` (>= 0; NaN and negatives count as 0).
    void observe(const FrameChoice& used, double seconds);

    [[nodiscard]] double work() const { return work_; }  // < 0 before the first observe()
    [[nodiscard]] const FrameTimeTarget& target() const { return target_; }

private:
    FrameTimeTarget target_;
    double work_ = -1.0;
};

}  // namespace mogao
