// SPDX-License-Identifier: Apache-2.0
// A camera ray's hit on the screen (cylinder_hit, screen_geometry.h): on a bowed screen the hit must lie on the
// surface and be the ray's first crossing of it, checked against a bisection that knows nothing of the solver's
// Newton steps and slopes; on a plain cylinder it is the closed form.
#include <cmath>
#include <numbers>
#include <optional>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "appliance/autocal/autocal.h"
#include "appliance/autocal/screen_geometry.h"

namespace mogao::autocal {
namespace {

ScreenModel bowed() {
    ScreenModel s;
    s.radius_m = 3.0;
    s.arc_deg = 150.0;
    s.bottom_m = 0.8;
    s.top_m = 2.3;
    s.bow_m = {0.03, -0.012, 0.018, 0.006};
    return s;
}

// Distance of o + t d from the axis minus the screen's radius there (screen_radius_at): zero on the surface.
double gap(const ScreenModel& s, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t) {
    const Eigen::Vector3d p = o + t * d;
    return std::sqrt(p.x() * p.x() + p.z() * p.z()) - screen_radius_at(s, std::atan2(p.x(), -p.z()), p.y());
}

// The root by plain bisection between the cylinders of radius R -/+ the bow's largest excursion.
double bisected(const ScreenModel& s, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
    double lo = 0.0;
    double hi = 100.0;
    for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        (gap(s, o, d, mid) < 0.0 ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

TEST(CylinderHit, BowedScreenHitMatchesBisectionOnEveryRay) {
    const ScreenModel s = bowed();
    const Eigen::Vector3d o(0.2, 1.4, -0.3);  // a camera inside the screen, off its axis
    int hits = 0;
    for (int i = -20; i <= 20; ++i) {
        for (int j = -10; j <= 10; ++j) {
            const double yaw = i * 4.0 * std::numbers::pi / 180.0;
            const double pitch = j * 3.0 * std::numbers::pi / 180.0;
            const Eigen::Vector3d d(std::sin(yaw) * std::cos(pitch), std::sin(pitch), -std::cos(yaw) * std::cos(pitch));
            const std::optional<Eigen::Vector3d> hit = cylinder_hit(s, o, d);
            ASSERT_TRUE(hit.has_value()) << "yaw " << i * 4 << " deg, pitch " << j * 3 << " deg";
            const double t = bisected(s, o, d);
            EXPECT_LT((*hit - (o + t * d)).norm(), 1e-9) << "yaw " << i * 4 << " deg, pitch " << j * 3 << " deg";
            const Eigen::Vector3d p = *hit;
            EXPECT_LT(std::abs(std::sqrt(p.x() * p.x() + p.z() * p.z()) -
                               screen_radius_at(s, std::atan2(p.x(), -p.z()), p.y())),
                      1e-11);
            ++hits;
        }
    }
    EXPECT_EQ(hits, 41 * 21);
}

TEST(CylinderHit, PlainCylinderIsTheClosedFormAndAVerticalRayMisses) {
    ScreenModel s = bowed();
    s.bow_m = {};
    const Eigen::Vector3d o(0.0, 1.5, 0.0);
    const auto hit = cylinder_hit(s, o, Eigen::Vector3d(0.6, 0.1, -0.8));
    ASSERT_TRUE(hit.has_value());
    EXPECT_NEAR(std::hypot(hit->x(), hit->z()), 3.0, 1e-12);
    EXPECT_NEAR(hit->x() / 0.6, -hit->z() / 0.8, 1e-12);  // on the ray
    EXPECT_FALSE(cylinder_hit(s, o, Eigen::Vector3d(0.0, 1.0, 0.0)).has_value());
    EXPECT_FALSE(cylinder_hit(bowed(), o, Eigen::Vector3d(0.0, 1.0, 0.0)).has_value());
}

}  // namespace
}  // namespace mogao::autocal
