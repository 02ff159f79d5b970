// SPDX-License-Identifier: Apache-2.0
#include "appliance/navigation/navigator.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace mogao {
namespace {

constexpr double kToRad = std::numbers::pi / 180.0;

void positive(const char* name, double v) {
    if (!(v > 0.0 && std::isfinite(v))) {
        throw std::invalid_argument(std::string("NavigationParams.") + name + " = " + std::to_string(v) +
                                    " must be finite and > 0");
    }
}

double dead_zone(double e, double zone) { return std::copysign(std::max(0.0, std::abs(e) - zone), e); }

}  // namespace

void validate(const NavigationParams& p) {
    validate(p.turn, "NavigationParams.turn");
    validate(p.forward, "NavigationParams.forward");
    validate(p.strafe, "NavigationParams.strafe");
    positive("rest.distance_m", p.rest.distance_m);
    if (!(std::isfinite(p.rest.yaw_deg) && std::isfinite(p.rest.pitch_deg) && std::isfinite(p.rest.lateral_m))) {
        throw std::invalid_argument("NavigationParams.rest: yaw, pitch and lateral must be finite");
    }
    if (!(p.pitch.dead_zone_deg >= 0.0 && std::isfinite(p.pitch.gain) && p.pitch.max_deg >= 0.0 &&
          p.pitch.max_deg <= 89.0)) {
        throw std::invalid_argument("NavigationParams.pitch: dead_zone_deg >= 0, finite gain, max_deg in [0, 89]");
    }
    positive("max_angular_accel_deg_s2", p.max_angular_accel_deg_s2);
    positive("max_linear_accel_m_s2", p.max_linear_accel_m_s2);
    positive("max_pitch_rate_deg_s", p.max_pitch_rate_deg_s);
    positive("max_dt_s", p.max_dt_s);
    if (!(p.hold_s >= 0.0 && p.hold_s <= p.forget_s && std::isfinite(p.forget_s))) {
        throw std::invalid_argument("NavigationParams: need 0 <= hold_s (" + std::to_string(p.hold_s) +
                                    ") <= forget_s (" + std::to_string(p.forget_s) + ")");
    }
    if (!std::isfinite(p.eye_height_m)) throw std::invalid_argument("NavigationParams.eye_height_m must be finite");
}

Navigator::Navigator(const NavigationParams& params, const ViewerPose& start)
    : params_(params),
      pose_(start),
      gate_(params.gate),
      yaw_filter_(params.angle_filter),
      pitch_filter_(params.angle_filter),
      lateral_filter_(params.length_filter),
      distance_filter_(params.length_filter) {
    validate(params_);
    if (!(start.eye.allFinite() && std::isfinite(start.yaw_deg) && std::isfinite(start.pitch_deg))) {
        throw std::invalid_argument("Navigator: start pose is not finite");
    }
    pose_.eye.y() = params_.eye_height_m;
}

void Navigator::observe(const TagSample& sample) {
    if (!sample.visible || !sample.rotation.allFinite() || !sample.translation_m.allFinite()) return;
    if (have_sample_ && static_cast<double>(sample.time_ns - last_accepted_ns_) > params_.forget_s * 1e9) {
        gate_.reset();
        yaw_filter_.reset();
        pitch_filter_.reset();
        lateral_filter_.reset();
        distance_filter_.reset();
    }
    const ControlSignals raw = control_signals(sample.rotation, sample.translation_m);
    const double t = static_cast<double>(sample.time_ns) * 1e-9;
    if (!gate_.accept(raw, t)) {
        ++rejected_total_;
        return;
    }
    filtered_.yaw_deg = yaw_filter_.filter(raw.yaw_deg, t);
    filtered_.pitch_deg = pitch_filter_.filter(raw.pitch_deg, t);
    filtered_.lateral_m = lateral_filter_.filter(raw.lateral_m, t);
    filtered_.distance_m = distance_filter_.filter(raw.distance_m, t);

    const RestPose& rest = params_.rest;
    commanded_.turn_deg_s = rate_from_offset(filtered_.yaw_deg - rest.yaw_deg, params_.turn);
    commanded_.forward_m_s = rate_from_offset(rest.distance_m - filtered_.distance_m, params_.forward);
    commanded_.strafe_m_s = rate_from_offset(rest.lateral_m - filtered_.lateral_m, params_.strafe);
    const PitchControl& pc = params_.pitch;
    pitch_target_deg_ = pc.enabled
                            ? std::clamp(pc.gain * dead_zone(filtered_.pitch_deg - rest.pitch_deg, pc.dead_zone_deg),
                                         -pc.max_deg, pc.max_deg)
                            : 0.0;
    have_sample_ = true;
    last_accepted_ns_ = sample.time_ns;
}

ViewerPose Navigator::advance(std::int64_t display_time_ns) {
    if (!have_display_time_) {
        have_display_time_ = true;
        last_display_ns_ = display_time_ns;
        return pose_;
    }
    const double dt = std::clamp(static_cast<double>(display_time_ns - last_display_ns_) * 1e-9, 0.0, params_.max_dt_s);
    last_display_ns_ = std::max(last_display_ns_, display_time_ns);
    tracking_ = have_sample_ && static_cast<double>(display_time_ns - last_accepted_ns_) <= params_.hold_s * 1e9;

    const Velocity target = tracking_ ? commanded_ : Velocity{};
    const Velocity before = velocity_;
    velocity_.turn_deg_s = slew_toward(velocity_.turn_deg_s, target.turn_deg_s, params_.max_angular_accel_deg_s2 * dt);
    velocity_.forward_m_s = slew_toward(velocity_.forward_m_s, target.forward_m_s, params_.max_linear_accel_m_s2 * dt);
    velocity_.strafe_m_s = slew_toward(velocity_.strafe_m_s, target.strafe_m_s, params_.max_linear_accel_m_s2 * dt);
    const double pitch_goal = tracking_ ? pitch_target_deg_ : 0.0;
    pose_.pitch_deg = slew_toward(pose_.pitch_deg, pitch_goal, params_.max_pitch_rate_deg_s * dt);

    // Trapezoidal integration: the mean of the velocities at both ends of the step, with the
    // direction of travel taken at the step's middle yaw.
    const double yaw_before = pose_.yaw_deg;
    pose_.yaw_deg += 0.5 * (before.turn_deg_s + velocity_.turn_deg_s) * dt;
    const double yaw_mid = 0.5 * (yaw_before + pose_.yaw_deg) * kToRad;
    const double forward = 0.5 * (before.forward_m_s + velocity_.forward_m_s) * dt;
    const double strafe = 0.5 * (before.strafe_m_s + velocity_.strafe_m_s) * dt;
    pose_.eye.x() += -std::sin(yaw_mid) * forward + std::cos(yaw_mid) * strafe;
    pose_.eye.z() += -std::cos(yaw_mid) * forward - std::sin(yaw_mid) * strafe;
    pose_.eye.y() = params_.eye_height_m;
    return pose_;
}

}  // namespace mogao
