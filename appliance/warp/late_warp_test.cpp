// SPDX-License-Identifier: Apache-2.0
#include "appliance/warp/late_warp.h"

#include <gtest/gtest.h>

#include <cmath>

namespace mogao {
namespace {

// Screen angle of column centre u of a frame `arc` degrees and `width` columns wide
// (common/view_request.h, CylinderScreen).
double column_angle(double u, double arc, int width) { return -arc / 2 + arc * (u + 0.5) / width; }

TEST(LateWarp, GuardBandKeepsTheColumnPitchAndCentres) {
    CylinderScreen screen;
    screen.arc_deg = 150;
    auto g = guard_band(screen, {300, 100}, 10.0);
    ASSERT_TRUE(g) << g.error().message;
    EXPECT_EQ(g->guard_px, 20);  // 0.5 degree per column
    EXPECT_EQ(g->size, (ImageSize{340, 100}));
    EXPECT_DOUBLE_EQ(g->camera.arc_deg, 170.0);
    EXPECT_DOUBLE_EQ(g->guard_deg, 10.0);
    // Screen column x is guarded column x + 20, at the same angle.
    for (int x : {0, 1, 150, 299}) {
        EXPECT_NEAR(column_angle(x, 150, 300), column_angle(x + 20, 170, 340), 1e-12) << x;
    }
    auto none = guard_band(screen, {300, 100}, 0.0);
    ASSERT_TRUE(none);
    EXPECT_EQ(none->size, (ImageSize{300, 100}));
    EXPECT_DOUBLE_EQ(none->camera.arc_deg, 150.0);
}

TEST(LateWarp, GuardBandRefusesBadInputNamingTheLimit) {
    CylinderScreen screen;
    screen.arc_deg = 300;
    const auto too_wide = guard_band(screen, {300, 100}, 31.0);
    ASSERT_FALSE(too_wide);
    EXPECT_EQ(too_wide.code(), EINVAL);
    EXPECT_NE(too_wide.error().message.find("at most 30"), std::string::npos) << too_wide.error().message;
    EXPECT_FALSE(guard_band(screen, {300, 100}, -1.0));
    EXPECT_FALSE(guard_band(screen, {300, 100}, std::nan("")));
    EXPECT_FALSE(guard_band(screen, {0, 100}, 1.0));
}

// The ground truth is the camera model: with the eye on the axis, the ray through screen angle theta
// at yaw y has world azimuth theta - y. Displayed column x at yaw y1 must show the azimuth the
// frame rendered at yaw y0 holds at the column the shift fetches.
TEST(LateWarp, PureYawShiftIsExact) {
    const double arc = 150;
    const int width = 300;
    const double guard = 10;  // 20 columns
    const int guarded_width = 340;
    const double guarded_arc = 170;
    for (const double delta : {0.0, 2.0, -3.5, 0.25, 10.0}) {
        const ContentShift s = late_rotational_shift(arc, guard, delta);
        EXPECT_FALSE(s.clamped);
        EXPECT_DOUBLE_EQ(s.shift_deg, delta);
        const double y0 = 37.0;
        const double y1 = y0 + delta;
        for (int x = 0; x < width; x += 7) {
            const double screen_s = (x + 0.5) / width;             // normalised screen coordinate
            const double frame_s = screen_s * s.scale + s.offset;  // the guarded frame's
            const double frame_u = frame_s * guarded_width - 0.5;  // its column (fractional)
            const double shown = column_angle(frame_u, guarded_arc, guarded_width) - y0;
            const double wanted = column_angle(x, arc, width) - y1;
            EXPECT_NEAR(shown, wanted, 1e-9) << "delta " << delta << " column " << x;
            // A whole number of columns: delta / arc * width, to the right for a left turn.
            EXPECT_NEAR(frame_u, x + 20 - delta / arc * width, 1e-9);
        }
    }
}

TEST(LateWarp, ShiftIsClampedAtTheBandsEdge) {
    const ContentShift left = late_rotational_shift(150, 10, 25);
    EXPECT_TRUE(left.clamped);
    EXPECT_DOUBLE_EQ(left.shift_deg, 10);
    EXPECT_DOUBLE_EQ(left.offset, 0.0) << "the screen's first column is the band's first";
    const ContentShift right = late_rotational_shift(150, 10, -25);
    EXPECT_TRUE(right.clamped);
    EXPECT_DOUBLE_EQ(right.scale + right.offset, 1.0) << "the screen's last edge is the band's last";
    const ContentShift off = late_rotational_shift(150, 0, 5);
    EXPECT_DOUBLE_EQ(off.scale, 1.0);
    EXPECT_DOUBLE_EQ(off.offset, 0.0) << "no band: no shift";
    const ContentShift nan = late_rotational_shift(150, 10, std::nan(""));
    EXPECT_DOUBLE_EQ(nan.shift_deg, 0.0);
}

}  // namespace
}  // namespace mogao
