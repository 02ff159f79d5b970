// SPDX-License-Identifier: Apache-2.0
#include "bench/quality/quality_views.h"

#include <cmath>
#include <cstdio>
#include <variant>

#include "common/camera_path.h"

namespace mogao::quality {
namespace {

// Pose at `eye` looking at `target` (yaw 0 looks along -z, + turns left; + pitch looks up).
ViewerPose look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
    const Eigen::Vector3d d = (target - eye).normalized();
    constexpr double kDeg = 180.0 / 3.14159265358979323846;
    return {eye, std::atan2(-d.x(), -d.z()) * kDeg, std::asin(d.y()) * kDeg};
}

}  // namespace

std::vector<QualityView> quality_views(const Scene& scene, int width, int height) {
    std::vector<QualityView> views(4);
    views[0].name = "walk";
    views[0].label = "walk frame 30 (cylinder)";
    views[0].request.camera = CylinderScreen{3.0, 150.0, 0.2, 2.8, {0.0, 1.6, 0.0}};
    views[0].request.pose = make_camera_path("walk", scene.viewer, 60)[30];
    views[0].request.size = {width, height};
    const int pinhole_height = (width * 3 + 2) / 4;
    // The bali-mask scan stands at (-1.9, 0.5, 3.2) on its pedestal (scenes/grotto.json), facing the
    // room's wall behind it (rotated 20 degrees about +y, its face toward +z); the eye is 1 m in front
    // of its face, slightly above.
    views[1].name = "mask";
    views[1].label = "bali-mask close-up (pinhole)";
    views[1].request.camera = PinholeCamera{40.0};
    views[1].request.pose = look_at({-1.6, 1.0, 4.1}, {-1.9, 0.85, 3.2});
    views[1].request.size = {width, pinhole_height};
    // The gilt Buddha on the dais seen from the entrance side, as a visitor who stops.
    views[2].name = "still";
    views[2].label = "gilt Buddha still (pinhole)";
    views[2].request.camera = PinholeCamera{45.0};
    views[2].request.pose = look_at({0.8, 1.6, 3.2}, {0.0, 1.3, 0.0});
    views[2].request.size = {width, pinhole_height};
    // The room from near the entrance, wide: both wall lamps (x = -1.6 and +1.6 m, 2.6 m up), the area
    // light's pool on the floor and the sun's patch in one frame, the lights' shadows crossing.
    views[3].name = "room";
    views[3].label = "room with its lights (pinhole)";
    views[3].request.camera = PinholeCamera{65.0};
    views[3].request.pose = look_at({0.0, 1.6, 5.0}, {0.0, 1.6, 0.0});
    views[3].request.size = {width, pinhole_height};
    return views;
}

std::string describe_request(const ViewRequest& r) {
    char buf[512];
    std::string camera;
    if (const auto* p = std::get_if<PinholeCamera>(&r.camera)) {
        std::snprintf(buf, sizeof buf, "pinhole fov %.17g", p->vertical_fov_deg);
    } else {
        const auto& c = std::get<CylinderScreen>(r.camera);
        std::snprintf(buf, sizeof buf, "cylinder r %.17g arc %.17g y %.17g..%.17g eye %.17g %.17g %.17g", c.radius_m,
                      c.arc_deg, c.bottom_m, c.top_m, c.eye_m.x(), c.eye_m.y(), c.eye_m.z());
    }
    camera = buf;
    std::snprintf(buf, sizeof buf,
                  "; eye %.17g %.17g %.17g yaw %.17g pitch %.17g; size %dx%d; bounces %d ao %d area %d scale %.17g",
                  r.pose.eye.x(), r.pose.eye.y(), r.pose.eye.z(), r.pose.yaw_deg, r.pose.pitch_deg, r.size.width,
                  r.size.height, r.quality.max_bounces, r.quality.ao_samples, r.quality.area_light_samples,
                  r.quality.resolution_scale);
    return camera + buf;
}

}  // namespace mogao::quality
