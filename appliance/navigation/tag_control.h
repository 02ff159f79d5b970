// SPDX-License-Identifier: Apache-2.0
// The control signals navigation reads from the tag's pose: how the visitor turned, tilted and
// moved the tag. Pure functions.
//
// Input: the tracker's pose (appliance/tracker/tag_pose.h): rotation tag -> camera and the tag
// centre in the camera frame (OpenCV: x right, y down, z forward; metres). The camera faces the
// visitor, so the camera's +x is the visitor's LEFT.
//
// The angles come from the tag's face normal n = R (0, 0, 1) (pointing at the camera at rest,
// n = (0, 0, -1)), not from Euler angles, so rolling the tag in the hand changes neither:
//   yaw_deg   = atan2(n.x, -n.z)              + when the face turns toward camera +x, i.e. the
//                                              visitor turns the tag to their left
//   pitch_deg = atan2(-n.y, hypot(n.x, n.z))  + when the face tilts up
//   lateral_m = t.x                           + toward camera +x (the visitor's left)
//   distance_m = t.z                          distance along the optical axis
#pragma once

#include <Eigen/Core>

namespace mogao {

struct ControlSignals {
    double yaw_deg = 0.0;
    double pitch_deg = 0.0;
    double lateral_m = 0.0;
    double distance_m = 0.0;
};

[[nodiscard]] ControlSignals control_signals(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation_m);

}  // namespace mogao
