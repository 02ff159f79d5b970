// SPDX-License-Identifier: Apache-2.0
#include "appliance/navigation/tag_control.h"

#include <cmath>
#include <numbers>

namespace mogao {

ControlSignals control_signals(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation_m) {
    constexpr double kToDeg = 180.0 / std::numbers::pi;
    const Eigen::Vector3d n = rotation.col(2);
    ControlSignals s;
    s.yaw_deg = std::atan2(n.x(), -n.z()) * kToDeg;
    s.pitch_deg = std::atan2(-n.y(), std::hypot(n.x(), n.z())) * kToDeg;
    s.lateral_m = translation_m.x();
    s.distance_m = translation_m.z();
    return s;
}

}  // namespace mogao
