// SPDX-License-Identifier: Apache-2.0
// Navigator: the visitor's tag steers the virtual camera by rate control (seed paper). Tag samples
// arrive at the camera rate (observe), ViewerPoses leave at the display rate (advance); the
// velocities are integrated with dt from the timestamps. Pure: no clock, no I/O, no threads --
// same inputs, same poses.
//
// Per accepted tag sample (observe):
//   1. control_signals(): yaw, pitch, lateral offset, distance (tag_control.h)
//   2. FlipGate: implausibly fast changes are dropped (flip_gate.h)
//   3. One Euro filter per signal (one_euro_filter.h): `angle_filter` on yaw and pitch (degrees),
//      `length_filter` on lateral and distance (metres)
//   4. commanded velocities (rate_mapping.h), offsets from the rest pose:
//        turn    (deg/s, + = left)     = rate(yaw - rest.yaw_deg, turn)
//        forward (m/s,  + = forward)   = rate(rest.distance_m - distance, forward)  (tag toward the camera)
//        strafe  (m/s,  + = right)     = rate(rest.lateral_m - lateral, strafe)     (tag to the visitor's right)
//      and, if pitch.enabled, a view pitch (position control, not rate):
//        pitch   (deg)  = clamp(gain * deadzone(pitch - rest.pitch_deg), -max_deg, max_deg)
// Per display frame (advance(t)):
//   dt = clamp(t - t_previous, 0, max_dt_s); tracking = an accepted sample within hold_s before t
//   each velocity slews toward (tracking ? commanded : 0) by at most max_*_accel * dt: so a lost
//   tag decelerates the view at a constant rate to a stop, and re-acquiring it starts smoothly;
//   the view pitch moves toward its target (0 when not tracking) at most max_pitch_rate * dt;
//   yaw += mean(turn) dt; eye += (forward f(yaw_mid) + strafe r(yaw_mid)) dt with
//   f(yaw) = (-sin yaw, 0, -cos yaw), r(yaw) = (cos yaw, 0, -sin yaw) (view_request.h frame);
//   eye.y = eye_height_m always. After forget_s without an accepted sample the filters and the
//   gate restart, so a tag brought back is not compared with where it was left.
#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "appliance/navigation/flip_gate.h"
#include "appliance/navigation/one_euro_filter.h"
#include "appliance/navigation/rate_mapping.h"
#include "appliance/navigation/tag_control.h"
#include "common/view_request.h"

namespace mogao {

// One tracker output: the tag pose at the frame's capture time (TrackedTag in
// appliance/tracker/tag_tracker.h). time_ns must be on the same clock as advance()'s.
struct TagSample {
    std::int64_t time_ns = 0;
    bool visible = false;
    Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();   // tag -> camera
    Eigen::Vector3d translation_m = Eigen::Vector3d::Zero();  // tag centre, camera frame
};

// The pose at which the visitor's tag commands no motion.
struct RestPose {
    double yaw_deg = 0.0;
    double pitch_deg = 0.0;
    double distance_m = 0.5;  // a comfortable arm's length from the camera
    double lateral_m = 0.0;
};

struct PitchControl {
    bool enabled = false;  // off: the view stays level (the grotto is explored at eye height)
    double dead_zone_deg = 3.0;
    double gain = 1.0;
    double max_deg = 25.0;
};

struct NavigationParams {
    RestPose rest;
    RateAxis turn{4.0, 30.0, 45.0, 1.0};     // degrees -> deg/s
    RateAxis forward{0.03, 0.15, 1.0, 1.0};  // metres -> m/s
    RateAxis strafe{0.04, 0.15, 0.0, 1.0};   // metres -> m/s; 0 = off by default
    PitchControl pitch;
    OneEuroParams angle_filter{0.5, 0.05, 1.0};   // degrees, Hz per deg/s (navigation_bench, docs/tracking.md)
    OneEuroParams length_filter{0.5, 15.0, 1.0};  // metres, Hz per m/s: 0.2 m/s push -> 3.5 Hz
    FlipGateParams gate;
    double max_angular_accel_deg_s2 = 120.0;  // 45 deg/s -> 0 in 0.375 s
    double max_linear_accel_m_s2 = 2.0;       // 1 m/s -> 0 in 0.5 s
    double max_pitch_rate_deg_s = 60.0;
    double hold_s = 0.15;   // a tag unseen for less than this keeps its command (dropped frames)
    double forget_s = 0.5;  // unseen for longer: filters and gate restart
    double max_dt_s = 0.1;  // longer display steps are clamped: a stalled display never teleports
    double eye_height_m = 1.6;
};

// Throws std::invalid_argument naming the field and its limit.
void validate(const NavigationParams& params);

struct Velocity {
    double turn_deg_s = 0.0;  // + = turning left
    double forward_m_s = 0.0;
    double strafe_m_s = 0.0;  // + = to the right
};

class Navigator {
public:
    // Throws std::invalid_argument for bad params or a non-finite start pose.
    Navigator(const NavigationParams& params, const ViewerPose& start);

    // A tracker result (visible or not) at its capture time.
    void observe(const TagSample& sample);

    // The pose to display at `display_time_ns`. The first call only sets the time origin.
    [[nodiscard]] ViewerPose advance(std::int64_t display_time_ns);

    [[nodiscard]] const Velocity& velocity() const { return velocity_; }    // as integrated
    [[nodiscard]] const Velocity& commanded() const { return commanded_; }  // from the last accepted sample
    [[nodiscard]] bool tracking() const { return tracking_; }               // as of the last advance()
    [[nodiscard]] const ControlSignals& filtered() const { return filtered_; }
    [[nodiscard]] int rejected_samples() const { return rejected_total_; }  // by the FlipGate, in all
    [[nodiscard]] const ViewerPose& pose() const { return pose_; }

private:
    NavigationParams params_;
    ViewerPose pose_;
    FlipGate gate_;
    OneEuroFilter yaw_filter_, pitch_filter_, lateral_filter_, distance_filter_;
    ControlSignals filtered_;
    Velocity commanded_;
    Velocity velocity_;
    double pitch_target_deg_ = 0.0;
    bool have_sample_ = false;
    std::int64_t last_accepted_ns_ = 0;
    bool have_display_time_ = false;
    std::int64_t last_display_ns_ = 0;
    bool tracking_ = false;
    int rejected_total_ = 0;
};

}  // namespace mogao
