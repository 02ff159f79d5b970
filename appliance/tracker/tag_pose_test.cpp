// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/tag_pose.h"

#include <gtest/gtest.h>

#include <random>

#include "appliance/tracker/lab/synthetic_view.h"

namespace mogao {
namespace {

TEST(TagPose, ExactCornersGiveTheExactPoseFirst) {
    const CameraIntrinsics cam = ideal_camera();
    for (const TagPose& truth :
         {tag_pose_facing_camera(0.5, 30.0, -10.0, 15.0, 0.05, 0.02),
          tag_pose_facing_camera(1.5, -50.0, 20.0, -100.0, -0.2, 0.1), tag_pose_facing_camera(0.3, 0.0, 70.0, 0.0)}) {
        const auto poses = solve_tag_pose(project_tag_corners(truth, cam, 0.1), cam, 0.1);
        ASSERT_FALSE(poses.empty());
        EXPECT_LT(rotation_angle_deg(poses[0].rotation, truth.rotation), 0.01);
        EXPECT_LT((poses[0].translation_m - truth.translation_m).norm(), 1e-5);
        EXPECT_LT(poses[0].reprojection_rms_px, 1e-6);
    }
}

TEST(TagPose, TheSecondSolutionMirrorsTheTilt) {
    const CameraIntrinsics cam = ideal_camera();
    const TagPose truth = tag_pose_facing_camera(0.8, 25.0);
    const auto poses = solve_tag_pose(project_tag_corners(truth, cam, 0.1), cam, 0.1);
    ASSERT_EQ(poses.size(), 2U);
    EXPECT_GT(rotation_angle_deg(poses[1].rotation, truth.rotation), 30.0);
    EXPECT_GT(poses[1].reprojection_rms_px, poses[0].reprojection_rms_px);
}

TEST(TagPose, DistortionIsTakenIntoAccount) {
    CameraIntrinsics cam = ideal_camera();
    cam.distortion = {-0.25, 0.08, 0.001, -0.0005, 0.0};
    const TagPose truth = tag_pose_facing_camera(0.6, 20.0, 10.0, 5.0, 0.15, 0.1);
    const auto poses = solve_tag_pose(project_tag_corners(truth, cam, 0.1), cam, 0.1);
    EXPECT_LT(rotation_angle_deg(poses[0].rotation, truth.rotation), 0.01);
    EXPECT_LT((poses[0].translation_m - truth.translation_m).norm(), 1e-5);
    // The same corners without the distortion model: a visibly different pose.
    const auto naive = solve_tag_pose(project_tag_corners(truth, cam, 0.1), ideal_camera(), 0.1);
    EXPECT_GT((naive[0].translation_m - truth.translation_m).norm(), 1e-3);
}

TEST(TagPose, BadInputIsRefused) {
    const CameraIntrinsics cam = ideal_camera();
    const auto corners = project_tag_corners(tag_pose_facing_camera(0.5, 0.0), cam, 0.1);
    EXPECT_THROW((void)solve_tag_pose(corners, cam, 0.0), std::invalid_argument);
    auto nan = corners;
    nan[2].x() = std::nan("");
    EXPECT_THROW((void)solve_tag_pose(nan, cam, 0.1), std::invalid_argument);
    CameraIntrinsics bad = cam;
    bad.fx = 0.0;
    EXPECT_THROW((void)solve_tag_pose(corners, bad, 0.1), std::invalid_argument);
}

TEST(TagPose, RotationAngle) {
    const TagPose a = tag_pose_facing_camera(1.0, 0.0);
    const TagPose b = tag_pose_facing_camera(1.0, 30.0);
    EXPECT_NEAR(rotation_angle_deg(a.rotation, b.rotation), 30.0, 1e-9);
    EXPECT_NEAR(rotation_angle_deg(a.rotation, a.rotation), 0.0, 1e-6);
}

}  // namespace
}  // namespace mogao
