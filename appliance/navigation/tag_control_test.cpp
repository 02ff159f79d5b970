// SPDX-License-Identifier: Apache-2.0
#include "appliance/navigation/tag_control.h"

#include <gtest/gtest.h>

#include "appliance/navigation/test_poses.h"

namespace mogao {
namespace {

TEST(TagControl, UprightTagFacingTheCameraIsZero) {
    const auto s = test::tag_sample(0, 0.0, 0.5);
    const ControlSignals c = control_signals(s.rotation, s.translation_m);
    EXPECT_NEAR(c.yaw_deg, 0.0, 1e-12);
    EXPECT_NEAR(c.pitch_deg, 0.0, 1e-12);
    EXPECT_NEAR(c.distance_m, 0.5, 1e-12);
    EXPECT_NEAR(c.lateral_m, 0.0, 1e-12);
}

TEST(TagControl, YawAndPitchFromTheFaceNormalIgnoreRoll) {
    for (double roll : {0.0, 30.0, -75.0}) {
        const auto s = test::tag_sample(0, 20.0, 0.4, 0.0, roll, 0.05);
        const ControlSignals c = control_signals(s.rotation, s.translation_m);
        EXPECT_NEAR(c.yaw_deg, 20.0, 1e-9) << "roll " << roll;
        EXPECT_NEAR(c.pitch_deg, 0.0, 1e-9) << "roll " << roll;
        EXPECT_NEAR(c.lateral_m, 0.05, 1e-12);
        EXPECT_NEAR(c.distance_m, 0.4, 1e-12);
    }
    const auto tilted = test::tag_sample(0, 0.0, 0.5, 15.0, 10.0);
    const ControlSignals c = control_signals(tilted.rotation, tilted.translation_m);
    EXPECT_NEAR(c.pitch_deg, 15.0, 1e-9);
    EXPECT_NEAR(c.yaw_deg, 0.0, 1e-9);
}

TEST(TagControl, FaceTurnedTowardCameraPlusXIsPositiveYaw) {
    // The face normal of a tag turned to the visitor's left points toward camera +x.
    const auto s = test::tag_sample(0, 10.0);
    EXPECT_GT(s.rotation.col(2).x(), 0.0);
    EXPECT_GT(control_signals(s.rotation, s.translation_m).yaw_deg, 0.0);
}

}  // namespace
}  // namespace mogao
