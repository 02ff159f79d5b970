// SPDX-License-Identifier: Apache-2.0
// FlipGate: rejects tag poses that moved faster than a hand can (a pose flip of the planar
// ambiguity the tracker could not resolve, or a misdetection), so one bad frame cannot reverse
// the turn direction.
//
// A sample is accepted when, against the last accepted sample dt seconds earlier,
//   |d yaw|, |d pitch|       <= max_angular_rate_deg_s * dt + angle_tolerance_deg
//   |d distance|, |d lateral| <= max_linear_rate_m_s * dt + distance_tolerance_m
// A genuine change (the visitor re-gripped the tag) persists: after `reacquire_samples`
// consecutive rejections the next sample is accepted and becomes the new reference. The IPPE
// flip of a tag tilted by theta jumps by about 2 theta; with the defaults at 30 Hz a jump above
// ~17 deg within one frame is rejected, far above the ~400 deg/s of a quick wrist turn
// (accepted: 400 deg/s * 33 ms = 13 deg).
#pragma once

#include "appliance/navigation/tag_control.h"

namespace mogao {

struct FlipGateParams {
    double max_angular_rate_deg_s = 360.0;  // > 0
    double angle_tolerance_deg = 5.0;       // >= 0: noise allowance
    double max_linear_rate_m_s = 2.0;       // > 0
    double distance_tolerance_m = 0.02;     // >= 0
    int reacquire_samples = 3;              // [1, 100]
};

class FlipGate {
public:
    // Throws std::invalid_argument naming the bad parameter and its limit.
    explicit FlipGate(const FlipGateParams& params = {});

    // Whether to use this sample (t_s: capture time, seconds). The first sample is accepted.
    [[nodiscard]] bool accept(const ControlSignals& signals, double t_s);

    void reset() {
        have_reference_ = false;
        rejected_ = 0;
    }
    [[nodiscard]] int consecutive_rejections() const { return rejected_; }

private:
    FlipGateParams params_;
    bool have_reference_ = false;
    ControlSignals reference_;
    double reference_t_ = 0.0;
    int rejected_ = 0;
};

}  // namespace mogao
