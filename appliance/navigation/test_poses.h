// SPDX-License-Identifier: Apache-2.0
// Test helper: the tag pose a visitor produces by turning (yaw), tilting (pitch) and rolling the
// tag at a distance, in the tracker's frames (tag_control.h). Same convention as the tracker's
// tag_pose_facing_camera (synthetic_view.h): R = diag(1,-1,-1) Ry(yaw) Rx(-pitch) Rz(roll).
#pragma once

#include <cstdint>
#include <numbers>

#include <Eigen/Geometry>

#include "appliance/navigation/navigator.h"

namespace mogao::test {

inline TagSample tag_sample(std::int64_t time_ns, double yaw_deg, double distance_m = 0.5, double pitch_deg = 0.0,
                            double roll_deg = 0.0, double lateral_m = 0.0) {
    constexpr double k = std::numbers::pi / 180.0;
    TagSample s;
    s.time_ns = time_ns;
    s.visible = true;
    s.rotation =
        Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal() * (Eigen::AngleAxisd(yaw_deg * k, Eigen::Vector3d::UnitY()) *
                                                         Eigen::AngleAxisd(-pitch_deg * k, Eigen::Vector3d::UnitX()) *
                                                         Eigen::AngleAxisd(roll_deg * k, Eigen::Vector3d::UnitZ()))
                                                            .toRotationMatrix();
    s.translation_m = {lateral_m, 0.0, distance_m};
    return s;
}

inline constexpr std::int64_t kMs = 1'000'000;

}  // namespace mogao::test
