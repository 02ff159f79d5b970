// SPDX-License-Identifier: Apache-2.0
// The tracker's pose disambiguation seen through the navigation's control signals: the yaw the
// navigation steers by must not flip between the two IPPE solutions of a small, noisy tag. Lives
// here because navigation may use the tracker, never the other way round.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "appliance/navigation/tag_control.h"
#include "appliance/tracker/lab/synthetic_view.h"
#include "appliance/tracker/pose_disambiguator.h"

namespace mogao {
namespace {

// A 10 cm tag 1.5 m away (47 px), turned 15 deg, its corners jittered by 0.25 px per frame: the
// two IPPE solutions (about +15 and -15 deg) have nearly the same error, and taking the best alone
// jumps between them (a pose flip: the yaw changes by more than 15 deg in one frame). With the
// disambiguator it never does. (Which of the two is right cannot be known from one such frame:
// that is the ambiguity; only the flips are avoidable.)
TEST(PoseDisambiguator, NoisyFarTagDoesNotFlipBetweenFrames) {
    const CameraIntrinsics cam = ideal_camera();
    const double yaw_deg = 15.0;
    const auto clean = project_tag_corners(tag_pose_facing_camera(1.5, yaw_deg), cam, 0.1);
    std::mt19937 rng(7);
    std::normal_distribution<double> noise(0.0, 0.25);
    PoseDisambiguator d;
    int best_flips = 0;
    int chosen_flips = 0;
    double best_before = 0.0;
    double chosen_before = 0.0;
    for (int frame = 0; frame < 200; ++frame) {
        auto corners = clean;
        for (auto& c : corners) c += Eigen::Vector2d(noise(rng), noise(rng));
        const auto candidates = solve_tag_pose(corners, cam, 0.1);
        const auto yaw = [](const TagPose& p) { return control_signals(p.rotation, p.translation_m).yaw_deg; };
        const double best = yaw(candidates[0]);
        const double chosen = yaw(d.choose(candidates));
        if (frame > 0) {
            best_flips += std::abs(best - best_before) > yaw_deg ? 1 : 0;
            chosen_flips += std::abs(chosen - chosen_before) > yaw_deg ? 1 : 0;
        }
        best_before = best;
        chosen_before = chosen;
    }
    EXPECT_GT(best_flips, 10);  // the ambiguity is real at this size and distance
    EXPECT_EQ(chosen_flips, 0);
}

}  // namespace
}  // namespace mogao
