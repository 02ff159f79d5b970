// SPDX-License-Identifier: Apache-2.0
#include "appliance/autocal/screen_bounce.h"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include <gtest/gtest.h>

namespace mogao::autocal {
namespace {

// A point at mid-height of a whole cylinder sees its wall with 1 - 2 F_end, F_end the configuration factor from a
// differential element on a cylinder's inside to the end disc at distance x: (X^2 + 2) / (2 sqrt(X^2 + 4)) - X / 2,
// X = x / R (Siegel & Howell, "Thermal Radiation Heat Transfer", catalogue of configuration factors). The patches'
// sum toward a uniformly lit wall must come within a few percent of it.
TEST(ScreenBounce, AWholeCylinderSeesItsWallWithTheCatalogueFactor) {
    ScreenModel whole;
    whole.radius_m = 3.0;
    whole.arc_deg = 359.99;
    whole.bottom_m = 0.8;
    whole.top_m = 2.3;
    const ScreenBounce patches(whole, 0.1);
    const std::vector<double> lit(static_cast<std::size_t>(patches.patches()), 1.0);
    const std::vector<double> bounce = patches.bounce(lit);
    const double x = 0.5 * (whole.top_m - whole.bottom_m) / whole.radius_m;
    const double f_end = (x * x + 2.0) / (2.0 * std::sqrt(x * x + 4.0)) - x / 2.0;
    const double mid = patches.at(bounce, 0.3, 0.5 * (whole.bottom_m + whole.top_m));
    EXPECT_NEAR(mid, 1.0 - 2.0 * f_end, 0.03 * (1.0 - 2.0 * f_end));
}

// Light from one side of an arc reaches the other side and not its own patch; the field is read bilinearly between
// patch centres and clamped beyond the outermost ones.
TEST(ScreenBounce, LightCrossesTheArcAndIsReadBetweenPatchCentres) {
    ScreenModel arc;  // 150 degrees, 3 m, 0.8 to 2.3 m
    const ScreenBounce patches(arc, 0.1);
    EXPECT_EQ(patches.columns(), static_cast<int>(std::lround(3.0 * 150.0 * std::numbers::pi / 180.0 / 0.1)));
    EXPECT_EQ(patches.rows(), 15);
    const int left = patches.patch_at(-1.2, 1.5);
    ASSERT_GE(left, 0);
    EXPECT_EQ(patches.patch_at(2.0, 1.5), -1);
    EXPECT_EQ(patches.patch_at(0.0, 0.5), -1);
    std::vector<double> leaving(static_cast<std::size_t>(patches.patches()), 0.0);
    leaving[static_cast<std::size_t>(left)] = 1.0;
    const std::vector<double> bounce = patches.bounce(leaving);
    EXPECT_EQ(bounce[static_cast<std::size_t>(left)], 0.0);
    EXPECT_GT(patches.at(bounce, 1.2, 1.5), 0.0);
    std::vector<double> ramp(static_cast<std::size_t>(patches.patches()));
    for (int r = 0; r < patches.rows(); ++r)
        for (int c = 0; c < patches.columns(); ++c) ramp[static_cast<std::size_t>(r * patches.columns() + c)] = c;
    const double dtheta = 150.0 * std::numbers::pi / 180.0 / patches.columns();
    EXPECT_NEAR(patches.at(ramp, -75.0 * std::numbers::pi / 180.0 + 3.25 * dtheta, 1.5), 2.75, 1e-9);
    EXPECT_NEAR(patches.at(ramp, -2.0, 1.5), 0.0, 1e-12);  // beyond the first centre: clamped
    EXPECT_THROW(ScreenBounce(arc, 0.001), std::invalid_argument);
    EXPECT_THROW((void)patches.bounce({1.0}), std::invalid_argument);
}

}  // namespace
}  // namespace mogao::autocal
