// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/trace/frame_projection.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <variant>

#include "common/cpu_level.h"

namespace mogao {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

// atan2(y, x) in float without libm's call: the ratio of the smaller to the larger magnitude in [0, 1],
// atan there by an odd polynomial of degree 15 (coefficients fitted to atan on [0, 1] by iteratively
// reweighted least squares toward the minimax, Lawson's algorithm; largest error 4e-8 rad, 1.1e-7
// rad evaluated in float), then the octant restored. libm's atan2f was a tenth of the admin's time
// on moving frames. 0 at (0, 0). Selects rather than branches, so that a loop over it vectorises.
MOGAO_ALWAYS_INLINE inline float fast_atan2(float y, float x) {
    const float ax = std::abs(x);
    const float ay = std::abs(y);
    const float hi = std::max(ax, ay);
    const float a = std::min(ax, ay) / std::max(hi, std::numeric_limits<float>::min());  // 0 at (0, 0)
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
    r = ay > ax ? std::numbers::pi_v<float> / 2.0f - r : r;
    r = x < 0.0f ? std::numbers::pi_v<float> - r : r;
    return y < 0.0f ? -r : r;
}

// The row loops of points_row and project_row, written once (cpu_level.h) and built for the
// baseline and for x86-64-v3; no branch in their bodies, so that GCC vectorises them.
struct RowRays {
    const float *cx, *cy, *cz;  // the columns' part of each ray direction
    float rx, ry, rz;           // the row's part
    float ex, ey, ez;           // the eye
};

// The constants are copied to locals and the arrays marked __restrict: otherwise GCC must assume
// that a store may change them, and does not vectorise.
MOGAO_ALWAYS_INLINE inline void points_body(const RowRays& r, const float* __restrict depth, int n,
                                            float* __restrict px, float* __restrict py, float* __restrict pz) {
    const float* __restrict cx = r.cx;
    const float* __restrict cy = r.cy;
    const float* __restrict cz = r.cz;
    const float rx = r.rx, ry = r.ry, rz = r.rz, ex = r.ex, ey = r.ey, ez = r.ez;
    for (int i = 0; i < n; ++i) {
        const float dx = cx[i] + rx;
        const float dy = cy[i] + ry;
        const float dz = cz[i] + rz;
        const float length = std::sqrt(dx * dx + dy * dy + dz * dz);
        px[i] = ex + depth[i] * (dx / length);
        py[i] = ey + depth[i] * (dy / length);
        pz[i] = ez + depth[i] * (dz / length);
    }
}

struct ProjectionConstants {
    float m[9];        // Rᵀ, row-major
    float ex, ey, ez;  // the eye
    // Cylinder: the physical eye (screen frame), c, the image scales. Pinhole: sx, sy, W/2, H/2.
    float sex, sey, sez, c, half_arc, px_per_rad, top, py_per_m;
    float sx, sy, half_w, half_h;
};

// The camera model's part of project(): pixel i's image position and answer from q = Rᵀ (p − eye).
struct CylinderProjection {
    MOGAO_ALWAYS_INLINE static void apply(const ProjectionConstants& k, float qx, float qy, float qz, float& px,
                                          float& py, std::uint8_t& ok) {
        const float a = qx * qx + qz * qz;
        const float b = 2.0f * (k.sex * qx + k.sez * qz);
        const float root = std::sqrt(std::max(b * b - 4.0f * a * k.c, 0.0f));
        const float s = b <= 0.0f ? (root - b) / (2.0f * a) : 2.0f * k.c / (-b - root);
        const float sx = k.sex + s * qx, sy = k.sey + s * qy, sz = k.sez + s * qz;
        px = (fast_atan2(sx, -sz) + k.half_arc) * k.px_per_rad;
        py = (k.top - sy) * k.py_per_m;
        ok = static_cast<std::uint8_t>(a > 0.0f && k.c < 0.0f);
    }
};
struct PinholeProjection {
    MOGAO_ALWAYS_INLINE static void apply(const ProjectionConstants& k, float qx, float qy, float qz, float& px,
                                          float& py, std::uint8_t& ok) {
        px = (qx / -qz * k.sx + 1.0f) * k.half_w;
        py = (1.0f - qy / -qz * k.sy) * k.half_h;
        ok = static_cast<std::uint8_t>(qz < 0.0f);
    }
};

template <typename Model>
MOGAO_ALWAYS_INLINE inline void project_body(const ProjectionConstants& constants, const float* __restrict x,
                                             const float* __restrict y, const float* __restrict z, int n,
                                             float* __restrict px, float* __restrict py, std::uint8_t* __restrict ok) {
    const ProjectionConstants k = constants;
    for (int i = 0; i < n; ++i) {
        const float dx = x[i] - k.ex, dy = y[i] - k.ey, dz = z[i] - k.ez;
        Model::apply(k, k.m[0] * dx + k.m[1] * dy + k.m[2] * dz, k.m[3] * dx + k.m[4] * dy + k.m[5] * dz,
                     k.m[6] * dx + k.m[7] * dy + k.m[8] * dz, px[i], py[i], ok[i]);
    }
}

MOGAO_TARGET_X86_64_V3 void points_v3(const RowRays& r, const float* depth, int n, float* px, float* py, float* pz) {
    points_body(r, depth, n, px, py, pz);
}
void points_base(const RowRays& r, const float* depth, int n, float* px, float* py, float* pz) {
    points_body(r, depth, n, px, py, pz);
}
MOGAO_TARGET_X86_64_V3 void project_cylinder_v3(const ProjectionConstants& k, const float* x, const float* y,
                                                const float* z, int n, float* px, float* py, std::uint8_t* ok) {
    project_body<CylinderProjection>(k, x, y, z, n, px, py, ok);
}
void project_cylinder_base(const ProjectionConstants& k, const float* x, const float* y, const float* z, int n,
                           float* px, float* py, std::uint8_t* ok) {
    project_body<CylinderProjection>(k, x, y, z, n, px, py, ok);
}
MOGAO_TARGET_X86_64_V3 void project_pinhole_v3(const ProjectionConstants& k, const float* x, const float* y,
                                               const float* z, int n, float* px, float* py, std::uint8_t* ok) {
    project_body<PinholeProjection>(k, x, y, z, n, px, py, ok);
}
void project_pinhole_base(const ProjectionConstants& k, const float* x, const float* y, const float* z, int n,
                          float* px, float* py, std::uint8_t* ok) {
    project_body<PinholeProjection>(k, x, y, z, n, px, py, ok);
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
        split_columns();
        return;
    }
    const double t = camera.tan_half_fov;
    for (std::size_t x = 0; x < columns_.size(); ++x)
        columns_[x] = (r.col(0) * ((2.0 * (static_cast<double>(x) + 0.5) / w - 1.0) * t * (w / h))).cast<float>();
    for (std::size_t y = 0; y < rows_.size(); ++y)
        rows_[y] = (r.col(1) * ((1.0 - 2.0 * (static_cast<double>(y) + 0.5) / h) * t) - r.col(2)).cast<float>();
    split_columns();
}

void PixelCentreRays::split_columns() {
    column_x_.resize(columns_.size());
    column_y_.resize(columns_.size());
    column_z_.resize(columns_.size());
    for (std::size_t x = 0; x < columns_.size(); ++x) {
        column_x_[x] = columns_[x].x();
        column_y_[x] = columns_[x].y();
        column_z_[x] = columns_[x].z();
    }
}

void PixelCentreRays::points_row(int y, const float* depth, int n, float* px, float* py, float* pz) const {
    const Eigen::Vector3f& row = rows_[static_cast<std::size_t>(y)];
    const RowRays r{column_x_.data(), column_y_.data(), column_z_.data(), row.x(), row.y(),
                    row.z(),          eye_.x(),         eye_.y(),         eye_.z()};
    if (use_x86_64_v3(CpuLevel::automatic)) points_v3(r, depth, n, px, py, pz);
    else points_base(r, depth, n, px, py, pz);
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

void FrameProjection::project_row(const float* x, const float* y, const float* z, int n, float* px, float* py,
                                  std::uint8_t* ok) const {
    ProjectionConstants k{};
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) k.m[3 * r + c] = to_camera_(r, c);
    k.ex = eye_.x(), k.ey = eye_.y(), k.ez = eye_.z();
    k.sex = screen_eye_.x(), k.sey = screen_eye_.y(), k.sez = screen_eye_.z();
    k.c = c_, k.half_arc = half_arc_, k.px_per_rad = px_per_rad_, k.top = top_, k.py_per_m = py_per_m_;
    k.sx = sx_, k.sy = sy_, k.half_w = half_w_, k.half_h = half_h_;
    const bool v3 = use_x86_64_v3(CpuLevel::automatic);
    if (cylinder_) (v3 ? project_cylinder_v3 : project_cylinder_base)(k, x, y, z, n, px, py, ok);
    else (v3 ? project_pinhole_v3 : project_pinhole_base)(k, x, y, z, n, px, py, ok);
}

}  // namespace mogao
