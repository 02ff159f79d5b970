// SPDX-License-Identifier: Apache-2.0
#include "common/camera_path.h"

#include <cmath>
#include <cstdio>
#include <fstream>

#include <gtest/gtest.h>

namespace mogao {
namespace {

Viewer test_viewer() {
    Viewer v;
    v.eye_height_m = 1.6;
    v.start = {0, 0, 6};
    return v;
}

Eigen::Vector3d forward(const ViewerPose& p) {
    const double a = p.yaw_deg * std::numbers::pi / 180;
    return {-std::sin(a), 0, -std::cos(a)};
}

TEST(CameraPath, WalkKeepsEyeHeightStartsAtTheStartAndEndsLookingAtTheCentre) {
    const auto poses = make_camera_path("walk", test_viewer(), 60);
    ASSERT_EQ(poses.size(), 60u);
    for (const ViewerPose& p : poses) EXPECT_DOUBLE_EQ(p.eye.y(), 1.6);
    EXPECT_NEAR((poses.front().eye - Eigen::Vector3d(0, 1.6, 6)).norm(), 0, 1e-12);
    const ViewerPose& last = poses.back();
    const Eigen::Vector3d to_centre = (Eigen::Vector3d(0, 1.6, 0) - last.eye).normalized();
    EXPECT_NEAR(forward(last).dot(to_centre), 1.0, 1e-9);
    // No jumps: consecutive eyes are close compared with the room (smooth walk).
    for (std::size_t i = 1; i < poses.size(); ++i) EXPECT_LT((poses[i].eye - poses[i - 1].eye).norm(), 0.6);
}

TEST(CameraPath, OrbitStaysOnTheCircleAndLooksAtTheCentre) {
    const auto poses = make_camera_path("orbit", test_viewer(), 37);
    for (const ViewerPose& p : poses) {
        EXPECT_NEAR(std::hypot(p.eye.x(), p.eye.z()), 6.0, 0.03);
        const Eigen::Vector3d to_centre = (Eigen::Vector3d(0, 1.6, 0) - p.eye).normalized();
        EXPECT_NEAR(forward(p).dot(to_centre), 1.0, 1e-3);
    }
}

TEST(CameraPath, PathFileIsInterpolatedAndBadFilesNameTheField) {
    const auto dir = std::filesystem::temp_directory_path();
    const auto good = dir / "mogao-path-good.json";
    std::ofstream(good) << R"({ "keyframes": [ { "position": [0, 0, 0], "yaw_deg": 170 },
                                               { "position": [2, 0, 0], "yaw_deg": -170 } ] })";
    const auto poses = read_path_file(good, test_viewer(), 3);
    ASSERT_EQ(poses.size(), 3u);
    EXPECT_NEAR(poses[1].eye.x(), 1.0, 1e-12);
    EXPECT_NEAR(std::remainder(poses[1].yaw_deg, 360.0), 180.0 * (poses[1].yaw_deg > 0 ? 1 : -1), 1e-9);  // shorter arc

    const auto bad = dir / "mogao-path-bad.json";
    std::ofstream(bad) << R"({ "keyframes": [ { "position": [0, "up", 0] } ] })";
    try {
        (void)read_path_file(bad, test_viewer(), 3);
        FAIL() << "accepted a non-numeric position";
    } catch (const PathError& e) {
        EXPECT_NE(std::string(e.what()).find("keyframes[0].position[1]"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(bad.string()), std::string::npos) << e.what();
    }
    EXPECT_THROW((void)make_camera_path("/nonexistent/path.json", test_viewer(), 3), PathError);
    EXPECT_THROW((void)make_camera_path("walk", test_viewer(), 0), PathError);
    std::filesystem::remove(good);
    std::filesystem::remove(bad);
}

}  // namespace
}  // namespace mogao
