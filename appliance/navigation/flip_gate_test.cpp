// SPDX-License-Identifier: Apache-2.0
#include "appliance/navigation/flip_gate.h"

#include <gtest/gtest.h>

namespace mogao {
namespace {

ControlSignals yaw(double deg) { return {deg, 0.0, 0.0, 0.5}; }

TEST(FlipGate, RejectsAFlipAcceptsAQuickTurn) {
    FlipGate gate;  // 360 deg/s + 5 deg
    const double dt = 1.0 / 30.0;
    ASSERT_TRUE(gate.accept(yaw(15.0), 0.0));
    EXPECT_FALSE(gate.accept(yaw(-15.0), dt));  // the mirrored IPPE pose: 30 deg in one frame
    EXPECT_EQ(gate.consecutive_rejections(), 1);
    EXPECT_TRUE(gate.accept(yaw(15.5), 2 * dt));  // measured against the last accepted sample
    EXPECT_TRUE(gate.accept(yaw(27.0), 3 * dt));  // 11.5 deg in a frame: a quick wrist turn
    EXPECT_EQ(gate.consecutive_rejections(), 0);
}

TEST(FlipGate, APersistentChangeIsAcceptedAfterReacquireSamples) {
    FlipGateParams p;
    p.reacquire_samples = 3;
    FlipGate gate(p);
    const double dt = 1.0 / 30.0;
    ASSERT_TRUE(gate.accept(yaw(0.0), 0.0));
    EXPECT_FALSE(gate.accept(yaw(60.0), dt));
    EXPECT_FALSE(gate.accept(yaw(60.0), 2 * dt));
    EXPECT_FALSE(gate.accept(yaw(60.0), 3 * dt));
    EXPECT_TRUE(gate.accept(yaw(60.0), 4 * dt));
    EXPECT_TRUE(gate.accept(yaw(61.0), 5 * dt));  // the new reference
}

TEST(FlipGate, DistanceJumpsAreGatedToo) {
    FlipGate gate;
    ASSERT_TRUE(gate.accept({0.0, 0.0, 0.0, 0.5}, 0.0));
    EXPECT_FALSE(gate.accept({0.0, 0.0, 0.0, 0.9}, 1.0 / 30.0));
    gate.reset();
    EXPECT_TRUE(gate.accept({0.0, 0.0, 0.0, 0.9}, 2.0 / 30.0));
}

TEST(FlipGate, BadParameters) {
    FlipGateParams p;
    p.reacquire_samples = 0;
    EXPECT_THROW(FlipGate{p}, std::invalid_argument);
    p = {};
    p.max_angular_rate_deg_s = 0.0;
    EXPECT_THROW(FlipGate{p}, std::invalid_argument);
}

}  // namespace
}  // namespace mogao
