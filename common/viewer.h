// SPDX-License-Identifier: Apache-2.0
// Where a scene's visitor starts: the eye height kept fixed while walking (the seed paper's
// navigation) and the start position and heading. A scene file's "viewer" block (scene/), the
// scripted paths (camera_path.h) and the kiosk's [navigation] section all use this one type.
// Units: metres, degrees; world frame as in view_request.h.
#pragma once

#include <Eigen/Core>

namespace mogao {

struct Viewer {
    double eye_height_m = 1.6;
    Eigen::Vector3d start{0.0, 0.0, 5.0};     // floor position of the viewer at start, world metres
    double start_yaw_deg = 0.0;
};

}  // namespace mogao
