// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/chessboard_calibration.h"

#include <unistd.h>

#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "appliance/tracker/lab/synthetic_view.h"
#include "tests/support/scratch_dir.h"

namespace mogao {
namespace {

namespace fs = std::filesystem;

class ChessboardFolder : public ::testing::Test {
protected:
    mogao::testing::ScratchDir scratch_{"chessboard"};
    void write(const std::string& name, const GrayImage& image) {
        const cv::Mat m(image.height, image.width, CV_8UC1, const_cast<std::uint8_t*>(image.pixels.data()));
        ASSERT_TRUE(cv::imwrite((dir_ / name).string(), m));
    }
    const fs::path dir_ = scratch_.path();
};

// Views of a 9x6 board from different angles, as a person calibrating would take them.
TEST_F(ChessboardFolder, RecoversTheCameraOfSyntheticViews) {
    CameraIntrinsics truth = ideal_camera(800, 600, 720.0);
    truth.cx = 405.0;
    truth.cy = 296.0;
    const PlanarTarget board = chessboard_target(9, 6, 0.025);
    const double views[][4] = {{0.45, 0, 0, 0},   {0.5, 30, 0, 5},   {0.5, -30, 5, -5},    {0.5, 0, 30, 0},
                               {0.5, 5, -30, 10}, {0.55, 25, 25, 0}, {0.45, -25, -20, 20}, {0.6, 35, -10, -15}};
    int i = 0;
    for (const auto& v : views) {
        RenderEffects fx;
        fx.noise_sigma = 1.0;
        fx.seed = static_cast<std::uint64_t>(i) + 1;
        fx.supersample = 4;
        write("view-" + std::to_string(i++) + ".png",
              render_target(board, tag_pose_facing_camera(v[0], v[1], v[2], v[3]), truth, fx));
    }
    write("zz-no-board.png", GrayImage(800, 600, 90));
    std::ofstream(dir_ / "notes.txt") << "ignored";

    const auto images = list_images(dir_);
    ASSERT_EQ(images.size(), 9U);
    const CalibrationResult r = calibrate_chessboard(images, {9, 6, 0.025});
    EXPECT_EQ(r.used.size(), 8U);
    ASSERT_EQ(r.rejected.size(), 1U);
    EXPECT_NE(r.rejected[0].find("zz-no-board.png: no 9x6 chessboard found"), std::string::npos) << r.rejected[0];
    EXPECT_LT(r.rms_px, 0.3);
    EXPECT_NEAR(r.intrinsics.fx, truth.fx, 0.01 * truth.fx);
    EXPECT_NEAR(r.intrinsics.fy, truth.fy, 0.01 * truth.fy);
    EXPECT_NEAR(r.intrinsics.cx, truth.cx, 3.0);
    EXPECT_NEAR(r.intrinsics.cy, truth.cy, 3.0);
    ASSERT_EQ(r.intrinsics.distortion.size(), 5U);
    EXPECT_NEAR(r.intrinsics.distortion[0], 0.0, 0.05);
    EXPECT_EQ(r.intrinsics.distortion[4], 0.0);  // k3 fixed
}

TEST_F(ChessboardFolder, TooFewViewsAndBadSpecsAreErrors) {
    write("flat.png", GrayImage(64, 48, 90));
    EXPECT_THROW((void)calibrate_chessboard(list_images(dir_), {9, 6, 0.025}), CalibrationError);
    EXPECT_THROW((void)calibrate_chessboard({}, {1, 6, 0.025}), std::invalid_argument);
    EXPECT_THROW((void)calibrate_chessboard({}, {9, 6, 0.0}), std::invalid_argument);
    EXPECT_THROW((void)list_images(dir_ / "absent"), CalibrationError);
}

}  // namespace
}  // namespace mogao
