// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/trace/camera.h"

#include <cmath>
#include <numbers>
#include <variant>

#include <Eigen/Geometry>

namespace mogao {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

}  // namespace

Eigen::Matrix3d pose_rotation(double yaw_deg, double pitch_deg) {
    const Eigen::AngleAxisd yaw(yaw_deg * kDegToRad, Eigen::Vector3d::UnitY());
    const Eigen::AngleAxisd pitch(pitch_deg * kDegToRad, Eigen::Vector3d::UnitX());
    return (yaw * pitch).toRotationMatrix();
}

CameraSetup make_camera_setup(const ViewRequest& request, ImageSize render_size) {
    CameraSetup setup{request.camera, render_size, request.pose.eye,
                      pose_rotation(request.pose.yaw_deg, request.pose.pitch_deg), 0.0};
    if (const auto* pinhole = std::get_if<PinholeCamera>(&request.camera)) {
        setup.tan_half_fov = std::tan(0.5 * pinhole->vertical_fov_deg * kDegToRad);
    }
    return setup;
}

Ray generate_ray(const CameraSetup& camera, double px, double py) {
    const double w = camera.size.width;
    const double h = camera.size.height;
    Eigen::Vector3d local;
    if (const auto* screen = std::get_if<CylinderScreen>(&camera.model)) {
        const double arc = screen->arc_deg * kDegToRad;
        const double theta = -0.5 * arc + arc * px / w;
        const double y = screen->top_m - (screen->top_m - screen->bottom_m) * py / h;
        const Eigen::Vector3d on_screen(screen->radius_m * std::sin(theta), y, -screen->radius_m * std::cos(theta));
        local = on_screen - screen->eye_m;
    } else {
        const double t = camera.tan_half_fov;
        local = Eigen::Vector3d((2.0 * px / w - 1.0) * t * (w / h), (1.0 - 2.0 * py / h) * t, -1.0);
    }
    return {camera.eye, (camera.rotation * local).normalized()};
}

}  // namespace mogao
