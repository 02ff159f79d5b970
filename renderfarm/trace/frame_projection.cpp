// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/trace/frame_projection.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <variant>

namespace mogao {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

// atan2(y, x) in float without libm's call: the ratio of the smaller to the larger magnitude in [0, 1],
// atan there by an odd polynomial of degree 15 (coefficients fitted to atan on [0, 1] by iteratively
// reweighted least squares toward the minimax, Lawson's algorithm; largest error 4e-8 rad, 1.1e-7
// rad evaluated in float), then the octant restored. libm's atan2f was a tenth of the admin's time
// on moving frames. 0 at (0, 0).
float fast_atan2(float y, float x) {
    const float ax = std::abs(x);
    const float ay = std::abs(y);
    const float hi = std::max(ax, ay);
    if (!(hi > 0.0f)) return 0.0f;
    const float a = std::min(ax, ay) / hi;
    const float a2 = a * a;
    float p = -0.0040547464f;
    p = p * a2 + 0.021863656f;
    p = p * a2 - 0.055913421f;
    p = p * a2 + 0.096422854f;
    p = p * a2 - 0.13908668f;
    p = p * a2 + 0.19946574f;
    p = p * a2 - 0.33329862f;
    p = p * a2 + 0.99999934f;
    float r = p * a;
    if (ay > ax) r = std::numbers::pi_v<float> / 2.0f - r;
    if (x < 0.0f) r = std::numbers::pi_v<float> - r;
    return y < 0.0f ? -r : r;
}

}  // namespace

PixelCentreRays::PixelCentreRays(const CameraSetup& camera) : eye_(camera.eye.cast<float>()) {
    const double w = camera.size.width;
    const double h = camera.size.height;
    columns_.resize(static_cast<std::size_t>(camera.size.width));
    rows_.resize(static_cast<std::size_t>(camera.size.height));
    const Eigen::Matrix3d& r = camera.rotation;
    if (const auto* screen = std::get_if<CylinderScreen>(&camera.model)) {
        const double arc = screen->arc_deg * kDegToRad;
        for (std::size_t x = 0; x < columns_.size(); ++x) {
            const double theta = -0.5 * arc + arc * (static_cast<double>(x) + 0.5) / w;
            columns_[x] =
                (r * Eigen::Vector3d(screen->radius_m * std::sin(theta), 0.0, -screen->radius_m * std::cos(theta)))
                    .cast<float>();
        }
        for (std::size_t y = 0; y < rows_.size(); ++y) {
            const double height =
                screen->top_m - (screen->top_m - screen->bottom_m) * (static_cast<double>(y) + 0.5) / h;
            rows_[y] = (r * (Eigen::Vector3d(0.0, height, 0.0) - screen->eye_m)).cast<float>();
        }
        return;
    }
    const double t = camera.tan_half_fov;
    for (std::size_t x = 0; x < columns_.size(); ++x)
        columns_[x] = (r.col(0) * ((2.0 * (static_cast<double>(x) + 0.5) / w - 1.0) * t * (w / h))).cast<float>();
    for (std::size_t y = 0; y < rows_.size(); ++y)
        rows_[y] = (r.col(1) * ((1.0 - 2.0 * (static_cast<double>(y) + 0.5) / h) * t) - r.col(2)).cast<float>();
}

FrameProjection::FrameProjection(const CameraSetup& camera)
    : to_camera_(camera.rotation.transpose().cast<float>()), eye_(camera.eye.cast<float>()) {
    const double w = camera.size.width;
    const double h = camera.size.height;
    if (const auto* screen = std::get_if<CylinderScreen>(&camera.model)) {
        cylinder_ = true;
        const Eigen::Vector3d& e = screen->eye_m;
        screen_eye_ = e.cast<float>();
        c_ = static_cast<float>(e.x() * e.x() + e.z() * e.z() - screen->radius_m * screen->radius_m);
        const double arc = screen->arc_deg * kDegToRad;
        half_arc_ = static_cast<float>(0.5 * arc);
        px_per_rad_ = static_cast<float>(w / arc);
        top_ = static_cast<float>(screen->top_m);
        py_per_m_ = static_cast<float>(h / (screen->top_m - screen->bottom_m));
        return;
    }
    const double t = camera.tan_half_fov;
    sx_ = static_cast<float>(1.0 / (t * (w / h)));
    sy_ = static_cast<float>(1.0 / t);
    half_w_ = static_cast<float>(0.5 * w);
    half_h_ = static_cast<float>(0.5 * h);
}

bool FrameProjection::project(const Eigen::Vector3f& p, float& px, float& py) const {
    const Eigen::Vector3f q = to_camera_ * (p - eye_);
    if (!cylinder_) {
        if (!(q.z() < 0.0f)) return false;
        px = (q.x() / -q.z() * sx_ + 1.0f) * half_w_;
        py = (1.0f - q.y() / -q.z() * sy_) * half_h_;
        return true;
    }
    const Eigen::Vector3f& e = screen_eye_;
    const float a = q.x() * q.x() + q.z() * q.z();
    const float b = 2.0f * (e.x() * q.x() + e.z() * q.z());
    if (!(a > 0.0f) || !(c_ < 0.0f)) return false;
    const float root = std::sqrt(b * b - 4.0f * a * c_);  // > |b|: c < 0
    // The positive root of a s² + b s + c: (−b + root) / 2a, or 2c / (−b − root) where b > 0 would cancel.
    const float s = b <= 0.0f ? (root - b) / (2.0f * a) : 2.0f * c_ / (-b - root);
    const Eigen::Vector3f on_screen = e + s * q;
    px = (fast_atan2(on_screen.x(), -on_screen.z()) + half_arc_) * px_per_rad_;
    py = (top_ - on_screen.y()) * py_per_m_;
    return true;
}

}  // namespace mogao
