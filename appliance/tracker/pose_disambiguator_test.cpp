// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/pose_disambiguator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "appliance/tracker/lab/synthetic_view.h"

namespace mogao {
namespace {

TagPose with_error(TagPose p, double rms) {
    p.reprojection_rms_px = rms;
    return p;
}

TEST(PoseDisambiguator, ClearWinnerIsTakenWhateverTheHistory) {
    PoseDisambiguator d;
    const TagPose a = with_error(tag_pose_facing_camera(0.5, 20.0), 0.1);
    const TagPose b = with_error(tag_pose_facing_camera(0.5, -20.0), 2.0);
    (void)d.choose(std::vector{b, a});  // history: the -20 deg pose
    const TagPose chosen = d.choose(std::vector{a, b});
    EXPECT_FALSE(d.last_was_ambiguous());
    EXPECT_LT(rotation_angle_deg(chosen.rotation, a.rotation), 1e-9);
}

TEST(PoseDisambiguator, AmbiguousPairFollowsTheHistory) {
    PoseDisambiguator d;
    const TagPose left = with_error(tag_pose_facing_camera(2.0, 8.0), 0.20);
    const TagPose right = with_error(tag_pose_facing_camera(2.0, -8.0), 0.21);
    const TagPose first = d.choose(std::vector{left, right});  // no history: the best
    EXPECT_TRUE(d.last_was_ambiguous());
    EXPECT_LT(rotation_angle_deg(first.rotation, left.rotation), 1e-9);
    // Next frame the noise makes the mirrored pose slightly better: continuity wins.
    const TagPose second = d.choose(std::vector{with_error(right, 0.19), with_error(left, 0.22)});
    EXPECT_LT(rotation_angle_deg(second.rotation, left.rotation), 1e-9);
    d.reset();
    const TagPose after_reset = d.choose(std::vector{with_error(right, 0.19), with_error(left, 0.22)});
    EXPECT_LT(rotation_angle_deg(after_reset.rotation, right.rotation), 1e-9);
    EXPECT_THROW((void)d.choose(std::span<const TagPose>{}), std::invalid_argument);
}

TEST(PoseDisambiguator, BadParameters) {
    EXPECT_THROW(PoseDisambiguator({0.5, 0.3}), std::invalid_argument);
    EXPECT_THROW(PoseDisambiguator({2.0, -1.0}), std::invalid_argument);
}

}  // namespace
}  // namespace mogao
