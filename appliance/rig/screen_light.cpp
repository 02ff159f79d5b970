// SPDX-License-Identifier: Apache-2.0
// Screen gain and screen-to-screen light of the virtual rig (screen_light.h; formulas in virtual_rig.h).
#include "appliance/rig/screen_light.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace mogao::rig {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kPatchM = 0.1;
constexpr int kMaxPatches = 4096;

// The cylinder's normal at theta, toward the axis (the bow's slope left out: validate_rig keeps it small).
Eigen::Vector3d inward_normal(double theta) { return {-std::sin(theta), 0.0, std::cos(theta)}; }

}  // namespace

double screen_gain(const RigScreen& screen, ScreenPoint s, const Eigen::Vector3d& source,
                   const Eigen::Vector3d& observer) {
    if (screen.gain == 1.0) return 1.0;
    const Eigen::Vector3d x = screen_position(screen, s);
    const Eigen::Vector3d n = inward_normal(s.theta_rad);
    const Eigen::Vector3d in = (x - source).normalized();
    const Eigen::Vector3d mirrored = in - 2.0 * in.dot(n) * n;
    const Eigen::Vector3d to_observer = (observer - x).normalized();
    const double alpha = std::acos(std::clamp(mirrored.dot(to_observer), -1.0, 1.0));
    const double t = alpha / (screen.half_gain_angle_deg * kDeg);
    return screen.gain * std::exp2(-t * t);
}

ScreenBounce::ScreenBounce(const RigScreen& screen) : screen_(screen) {
    const double arc = screen.arc_deg * kDeg;
    const double height = screen.top_m - screen.bottom_m;
    double patch = kPatchM;
    for (;;) {
        columns_ = std::max(2, static_cast<int>(std::ceil(screen.radius_m * arc / patch)));
        rows_ = std::max(2, static_cast<int>(std::ceil(height / patch)));
        if (columns_ * rows_ <= kMaxPatches) break;
        patch *= 1.25;
    }
    d_theta_ = arc / columns_;
    d_h_ = height / rows_;
    const int n = patches();
    std::vector<Eigen::Vector3d> position(static_cast<std::size_t>(n));
    std::vector<Eigen::Vector3d> normal(static_cast<std::size_t>(n));
    std::vector<double> area(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
        const ScreenPoint c = centre(i);
        position[static_cast<std::size_t>(i)] = screen_position(screen, c);
        normal[static_cast<std::size_t>(i)] = inward_normal(c.theta_rad);
        const Eigen::Vector3d p = position[static_cast<std::size_t>(i)];
        area[static_cast<std::size_t>(i)] = std::hypot(p.x(), p.z()) * d_theta_ * d_h_;
    }
    form_factors_.assign(static_cast<std::size_t>(n) * static_cast<std::size_t>(n), 0.0F);
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
            if (i == j) continue;
            const Eigen::Vector3d d = position[static_cast<std::size_t>(j)] - position[static_cast<std::size_t>(i)];
            const double d2 = d.squaredNorm();
            const double cos_i = normal[static_cast<std::size_t>(i)].dot(d) / std::sqrt(d2);
            const double cos_j = -normal[static_cast<std::size_t>(j)].dot(d) / std::sqrt(d2);
            if (cos_i <= 0.0 || cos_j <= 0.0) continue;
            form_factors_[static_cast<std::size_t>(i) * n + j] =
                static_cast<float>(cos_i * cos_j * area[static_cast<std::size_t>(j)] / (std::numbers::pi * d2));
        }
    }
}

ScreenPoint ScreenBounce::centre(int i) const {
    const int col = i % columns_;
    const int row = i / columns_;
    return {-screen_.arc_deg * kDeg / 2.0 + (col + 0.5) * d_theta_, screen_.top_m - (row + 0.5) * d_h_};
}

std::vector<double> ScreenBounce::bounce(const std::vector<double>& leaving) const {
    const int n = patches();
    if (static_cast<int>(leaving.size()) != n) {
        throw std::invalid_argument("ScreenBounce::bounce: " + std::to_string(leaving.size()) + " values for " +
                                    std::to_string(n) + " patches");
    }
    std::vector<double> out(static_cast<std::size_t>(n), 0.0);
    for (int i = 0; i < n; ++i) {
        double sum = 0.0;
        const float* f = form_factors_.data() + static_cast<std::size_t>(i) * n;
        for (int j = 0; j < n; ++j) sum += f[j] * leaving[static_cast<std::size_t>(j)];
        out[static_cast<std::size_t>(i)] = screen_.interreflection * sum;
    }
    return out;
}

double ScreenBounce::at(const std::vector<double>& field, ScreenPoint s) const {
    const double fx = std::clamp((s.theta_rad + screen_.arc_deg * kDeg / 2.0) / d_theta_ - 0.5, 0.0, columns_ - 1.0);
    const double fy = std::clamp((screen_.top_m - s.h_m) / d_h_ - 0.5, 0.0, rows_ - 1.0);
    const int x0 = std::min(static_cast<int>(fx), columns_ - 2);
    const int y0 = std::min(static_cast<int>(fy), rows_ - 2);
    const double ax = fx - x0;
    const double ay = fy - y0;
    const auto v = [&](int x, int y) { return field[static_cast<std::size_t>(y) * columns_ + x]; };
    return (1.0 - ay) * ((1.0 - ax) * v(x0, y0) + ax * v(x0 + 1, y0)) +
           ay * ((1.0 - ax) * v(x0, y0 + 1) + ax * v(x0 + 1, y0 + 1));
}

}  // namespace mogao::rig
