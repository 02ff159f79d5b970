// SPDX-License-Identifier: Apache-2.0
#include "appliance/navigation/flip_gate.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mogao {

FlipGate::FlipGate(const FlipGateParams& p) : params_(p) {
    const auto bad = [](const std::string& what) { throw std::invalid_argument("FlipGateParams." + what); };
    if (!(p.max_angular_rate_deg_s > 0.0 && std::isfinite(p.max_angular_rate_deg_s)))
        bad("max_angular_rate_deg_s must be > 0");
    if (!(p.angle_tolerance_deg >= 0.0 && std::isfinite(p.angle_tolerance_deg)))
        bad("angle_tolerance_deg must be >= 0");
    if (!(p.max_linear_rate_m_s > 0.0 && std::isfinite(p.max_linear_rate_m_s))) bad("max_linear_rate_m_s must be > 0");
    if (!(p.distance_tolerance_m >= 0.0 && std::isfinite(p.distance_tolerance_m)))
        bad("distance_tolerance_m must be >= 0");
    if (p.reacquire_samples < 1 || p.reacquire_samples > 100) {
        bad("reacquire_samples " + std::to_string(p.reacquire_samples) + " outside [1, 100]");
    }
}

bool FlipGate::accept(const ControlSignals& s, double t_s) {
    bool ok = true;
    if (have_reference_ && rejected_ < params_.reacquire_samples) {
        const double dt = std::max(0.0, t_s - reference_t_);
        const double angle = params_.max_angular_rate_deg_s * dt + params_.angle_tolerance_deg;
        const double length = params_.max_linear_rate_m_s * dt + params_.distance_tolerance_m;
        ok = std::abs(s.yaw_deg - reference_.yaw_deg) <= angle &&
             std::abs(s.pitch_deg - reference_.pitch_deg) <= angle &&
             std::abs(s.distance_m - reference_.distance_m) <= length &&
             std::abs(s.lateral_m - reference_.lateral_m) <= length;
    }
    if (!ok) {
        ++rejected_;
        return false;
    }
    have_reference_ = true;
    reference_ = s;
    reference_t_ = t_s;
    rejected_ = 0;
    return true;
}

}  // namespace mogao
