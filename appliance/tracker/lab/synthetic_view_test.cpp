// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/lab/synthetic_view.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace mogao {
namespace {

// A frontal 2x1 target (black cell left, white right) whose edge falls a quarter of a pixel into
// a pixel column: that column is exactly 25 % black. This pins the renderer's pixel convention
// (area averaging, pixel centres at +0.5) that the corner-error figures rely on.
TEST(SyntheticView, EdgesAreAreaAveragedAtTheDocumentedPixelPosition) {
    const CameraIntrinsics cam = ideal_camera(200, 100, 500.0);  // cx = 99.5: optical axis at x = 100.0
    PlanarTarget t;
    t.columns = 2;
    t.rows = 1;
    t.cell_m = 0.04;
    t.cells = {0, 255};
    // The edge at the target's centre, shifted right by 0.25 px at 1 m: 0.25 / 500 m.
    TagPose pose = tag_pose_facing_camera(1.0, 0.0, 0.0, 0.0, 0.25 / 500.0, 0.0);
    RenderEffects fx;
    fx.black = 0.0;
    fx.white = 200.0;
    fx.background = 100.0;
    fx.gradient = 0.0;
    const GrayImage image = render_target(t, pose, cam, fx);
    EXPECT_EQ(image.at(99, 50), 0);     // covers [99, 100): black
    EXPECT_EQ(image.at(100, 50), 150);  // covers [100, 101), edge at 100.25: 25 % black
    EXPECT_EQ(image.at(101, 50), 200);
    EXPECT_EQ(image.at(10, 50), 100);  // background
}

TEST(SyntheticView, PoseHelperSigns) {
    // yaw > 0 turns the face normal toward camera +x; pitch > 0 toward camera -y (up).
    EXPECT_GT(tag_pose_facing_camera(1.0, 20.0).rotation.col(2).x(), 0.1);
    EXPECT_LT(tag_pose_facing_camera(1.0, 0.0, 20.0).rotation.col(2).y(), -0.1);
    // roll > 0: counter-clockwise on screen, the bottom-right corner rises above the bottom-left.
    const auto c = project_tag_corners(tag_pose_facing_camera(1.0, 0.0, 0.0, 20.0), ideal_camera(), 0.1);
    EXPECT_LT(c[1].y(), c[0].y());
    // Upright: corner 0 bottom-left, 1 bottom-right, 2 top-right, 3 top-left (image y down).
    const auto u = project_tag_corners(tag_pose_facing_camera(1.0, 0.0), ideal_camera(), 0.1);
    EXPECT_LT(u[0].x(), u[1].x());
    EXPECT_GT(u[0].y(), u[3].y());
    EXPECT_NEAR(u[2].x(), 400.0 + 35.0, 1e-9);  // 0.05 m * 700 px / 1 m right of the centre (400.0)
}

TEST(SyntheticView, NoiseIsSeededAndEffectsAreChecked) {
    const PlanarTarget t = chessboard_target(3, 3, 0.02);
    const TagPose pose = tag_pose_facing_camera(0.5, 10.0);
    RenderEffects fx;
    fx.noise_sigma = 5.0;
    const GrayImage a = render_target(t, pose, ideal_camera(), fx);
    EXPECT_EQ(a.pixels, render_target(t, pose, ideal_camera(), fx).pixels);
    fx.seed = 2;
    EXPECT_NE(a.pixels, render_target(t, pose, ideal_camera(), fx).pixels);
    fx.noise_sigma = -1.0;
    EXPECT_THROW((void)render_target(t, pose, ideal_camera(), fx), std::invalid_argument);
    EXPECT_THROW((void)render_target(t, tag_pose_facing_camera(-0.5, 0.0), ideal_camera()), std::invalid_argument);
}

}  // namespace
}  // namespace mogao
