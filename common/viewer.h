// SPDX-License-Identifier: Apache-2.0
// Where a scene's visitor starts: the eye height kept fixed while walking (the seed paper's
// navigation) and the start position and heading. A scene file's "viewer" block (scene/), the
// scripted paths (camera_path.h) and the kiosk's [navigation] section all use this one type.
// Units: metres, degrees; world frame as in view_request.h.
#pragma once

#include <optional>

#include <Eigen/Core>

namespace mogao {

// Where a visitor may stand: a floor rectangle in world x and z (min_xz..max_xz), or, when radius_m
// > 0, the disc of that radius around centre_xz; and the range of the eye's world y
// (eye_min_m..eye_max_m). Metres. The scene file's "viewer.visitable" (docs/scene-format.md); the
// farm's view policy moves a requested eye into it (renderfarm/farm/view_policy.h), so that an
// appliance cannot ask for views from where no visitor of the museum's tour could stand.
struct VisitableArea {
    Eigen::Vector2d min_xz{0.0, 0.0};
    Eigen::Vector2d max_xz{0.0, 0.0};
    Eigen::Vector2d centre_xz{0.0, 0.0};
    double radius_m = 0.0;  // > 0: a disc instead of the rectangle
    double eye_min_m = 0.0;
    double eye_max_m = 0.0;
};

struct Viewer {
    double eye_height_m = 1.6;
    Eigen::Vector3d start{0.0, 0.0, 5.0};  // floor position of the viewer at start, world metres
    double start_yaw_deg = 0.0;
    std::optional<VisitableArea> visitable;  // none: anywhere
};

}  // namespace mogao
