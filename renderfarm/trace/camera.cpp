// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/trace/camera.h"

#include <algorithm>
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

double camera_cone_spread(const CameraSetup& camera, int spp) {
    double spread = 0.0;
    if (const auto* screen = std::get_if<CylinderScreen>(&camera.model)) {
        const double pixel_m = std::max((screen->top_m - screen->bottom_m) / camera.size.height,
                                        screen->radius_m * screen->arc_deg * kDegToRad / camera.size.width);
        const Eigen::Vector3d centre(0.0, 0.5 * (screen->top_m + screen->bottom_m), -screen->radius_m);
        const double distance = (centre - screen->eye_m).norm();
        spread = distance > 0.0 ? std::atan(pixel_m / distance) : 0.0;
    } else {
        spread = std::atan(2.0 * camera.tan_half_fov / camera.size.height);
    }
    return spp > 1 ? spread * std::max(0.125, 1.0 / std::sqrt(static_cast<double>(spp))) : spread;
}

namespace {

// The screen angle of image column position px (camera.h).
double cylinder_theta(const CylinderScreen& screen, double px, double width) {
    const double arc = screen.arc_deg * kDegToRad;
    return -0.5 * arc + arc * px / width;
}

Ray cylinder_ray(const CameraSetup& camera, const CylinderScreen& screen, double sin_theta, double cos_theta,
                 double py) {
    const double y = screen.top_m - (screen.top_m - screen.bottom_m) * py / camera.size.height;
    const Eigen::Vector3d on_screen(screen.radius_m * sin_theta, y, -screen.radius_m * cos_theta);
    return {camera.eye, (camera.rotation * (on_screen - screen.eye_m)).normalized()};
}

}  // namespace

CylinderColumns make_cylinder_columns(const CameraSetup& camera) {
    CylinderColumns columns;
    const auto* screen = std::get_if<CylinderScreen>(&camera.model);
    if (screen == nullptr) return columns;
    const auto width = static_cast<std::size_t>(camera.size.width);
    columns.sin_theta.resize(width);
    columns.cos_theta.resize(width);
    for (std::size_t x = 0; x < width; ++x) {
        const double theta = cylinder_theta(*screen, static_cast<double>(x) + 0.5, camera.size.width);
        columns.sin_theta[x] = std::sin(theta);
        columns.cos_theta[x] = std::cos(theta);
    }
    return columns;
}

Ray generate_column_ray(const CameraSetup& camera, const CylinderColumns& columns, int x, double py) {
    const auto* screen = std::get_if<CylinderScreen>(&camera.model);
    const auto column = static_cast<std::size_t>(x);
    if (screen == nullptr || column >= columns.sin_theta.size()) return generate_ray(camera, x + 0.5, py);
    return cylinder_ray(camera, *screen, columns.sin_theta[column], columns.cos_theta[column], py);
}

Ray generate_ray(const CameraSetup& camera, double px, double py) {
    const double w = camera.size.width;
    const double h = camera.size.height;
    if (const auto* screen = std::get_if<CylinderScreen>(&camera.model)) {
        const double theta = cylinder_theta(*screen, px, w);
        return cylinder_ray(camera, *screen, std::sin(theta), std::cos(theta), py);
    }
    const double t = camera.tan_half_fov;
    const Eigen::Vector3d local((2.0 * px / w - 1.0) * t * (w / h), (1.0 - 2.0 * py / h) * t, -1.0);
    return {camera.eye, (camera.rotation * local).normalized()};
}

bool project_to_image(const CameraSetup& camera, const Eigen::Vector3d& p, double& px, double& py) {
    const double w = camera.size.width;
    const double h = camera.size.height;
    const Eigen::Vector3d q = camera.rotation.transpose() * (p - camera.eye);
    if (const auto* screen = std::get_if<CylinderScreen>(&camera.model)) {
        const Eigen::Vector3d& e = screen->eye_m;
        const double a = q.x() * q.x() + q.z() * q.z();
        const double b = 2.0 * (e.x() * q.x() + e.z() * q.z());
        const double c = e.x() * e.x() + e.z() * e.z() - screen->radius_m * screen->radius_m;
        if (!(a > 0.0) || !(c < 0.0)) return false;
        const double s = (-b + std::sqrt(b * b - 4.0 * a * c)) / (2.0 * a);  // c < 0: one positive root
        const Eigen::Vector3d on_screen = e + s * q;
        const double arc = screen->arc_deg * kDegToRad;
        px = (std::atan2(on_screen.x(), -on_screen.z()) + 0.5 * arc) / arc * w;
        py = (screen->top_m - on_screen.y()) / (screen->top_m - screen->bottom_m) * h;
        return true;
    }
    if (!(q.z() < 0.0)) return false;
    const double t = camera.tan_half_fov;
    px = 0.5 * (q.x() / -q.z() / (t * (w / h)) + 1.0) * w;
    py = 0.5 * (1.0 - q.y() / -q.z() / t) * h;
    return true;
}

}  // namespace mogao
