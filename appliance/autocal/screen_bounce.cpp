// SPDX-License-Identifier: Apache-2.0
#include "appliance/autocal/screen_bounce.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

#include "appliance/autocal/screen_geometry.h"

namespace mogao::autocal {

ScreenBounce::ScreenBounce(const ScreenModel& screen, double patch_m) {
    if (!(patch_m >= 0.01 && patch_m <= 1.0))
        throw std::invalid_argument("screen bounce: patch size " + std::to_string(patch_m) + " m outside [0.01, 1]");
    const double arc = screen.arc_deg * std::numbers::pi / 180.0;
    const double height = screen.top_m - screen.bottom_m;
    if (!(arc > 0.0 && height > 0.0 && screen.radius_m > 0.0))
        throw std::invalid_argument("screen bounce: the screen has no area");
    columns_ = std::max(1, static_cast<int>(std::lround(screen.radius_m * arc / patch_m)));
    rows_ = std::max(1, static_cast<int>(std::lround(height / patch_m)));
    dtheta_ = arc / columns_;
    dh_ = height / rows_;
    theta0_ = -arc / 2.0;
    h0_ = screen.bottom_m;
    const auto n = static_cast<std::size_t>(patches());
    std::vector<Eigen::Vector3d> centre(n), normal(n);
    std::vector<double> area(n);
    for (int r = 0; r < rows_; ++r) {
        for (int c = 0; c < columns_; ++c) {
            const double theta = theta0_ + (c + 0.5) * dtheta_;
            const double h = h0_ + (r + 0.5) * dh_;
            const auto i = static_cast<std::size_t>(r * columns_ + c);
            centre[i] = screen_position(screen, theta, h);
            // The surface's tangents by central differences (the bow bends it): area and inward normal.
            const Eigen::Vector3d dt =
                (screen_position(screen, theta + 0.5 * dtheta_, h) - screen_position(screen, theta - 0.5 * dtheta_, h));
            const Eigen::Vector3d dv =
                (screen_position(screen, theta, h + 0.5 * dh_) - screen_position(screen, theta, h - 0.5 * dh_));
            const Eigen::Vector3d cross = dt.cross(dv);
            area[i] = cross.norm();
            normal[i] = cross.normalized();
            const Eigen::Vector3d to_axis(-centre[i].x(), 0.0, -centre[i].z());
            if (normal[i].dot(to_axis) < 0.0) normal[i] = -normal[i];
        }
    }
    form_.assign(n * n, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j = 0; j < n; ++j) {
            if (i == j) continue;
            const Eigen::Vector3d d = centre[j] - centre[i];
            const double d2 = d.squaredNorm();
            const double cos_i = normal[i].dot(d) / std::sqrt(d2);
            const double cos_j = -normal[j].dot(d) / std::sqrt(d2);
            if (cos_i <= 0.0 || cos_j <= 0.0) continue;
            form_[i * n + j] = cos_i * cos_j * area[j] / (std::numbers::pi * d2);
        }
    }
}

int ScreenBounce::patch_at(double theta, double h) const {
    const int c = static_cast<int>(std::floor((theta - theta0_) / dtheta_));
    const int r = static_cast<int>(std::floor((h - h0_) / dh_));
    if (c < 0 || r < 0 || c >= columns_ || r >= rows_) return -1;
    return r * columns_ + c;
}

std::vector<double> ScreenBounce::bounce(const std::vector<double>& leaving) const {
    const auto n = static_cast<std::size_t>(patches());
    if (leaving.size() != n)
        throw std::invalid_argument("screen bounce: " + std::to_string(leaving.size()) + " patch values for " +
                                    std::to_string(n) + " patches");
    std::vector<double> out(n, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
        double sum = 0.0;
        for (std::size_t j = 0; j < n; ++j) sum += form_[i * n + j] * leaving[j];
        out[i] = sum;
    }
    return out;
}

double ScreenBounce::at(const std::vector<double>& field, double theta, double h) const {
    const double u = std::clamp((theta - theta0_) / dtheta_ - 0.5, 0.0, static_cast<double>(columns_ - 1));
    const double v = std::clamp((h - h0_) / dh_ - 0.5, 0.0, static_cast<double>(rows_ - 1));
    const int c0 = std::min(static_cast<int>(u), columns_ - 1), r0 = std::min(static_cast<int>(v), rows_ - 1);
    const int c1 = std::min(c0 + 1, columns_ - 1), r1 = std::min(r0 + 1, rows_ - 1);
    const double fu = u - c0, fv = v - r0;
    const auto f = [&](int r, int c) { return field[static_cast<std::size_t>(r * columns_ + c)]; };
    return (1 - fv) * ((1 - fu) * f(r0, c0) + fu * f(r0, c1)) + fv * ((1 - fu) * f(r1, c0) + fu * f(r1, c1));
}

}  // namespace mogao::autocal
