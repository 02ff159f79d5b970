// SPDX-License-Identifier: Apache-2.0
// RequestPace: a slow appliance's period becomes the target (clamped); one that waits for the farm keeps it.
#include "renderfarm/schedule/request_pace.h"

#include <gtest/gtest.h>

namespace mogao {
namespace {

constexpr double kShare = 0.85;

TEST(RequestPace, ASlowAppliancesPeriodBecomesTheTargetWithinItsBounds) {
    RequestPace pace;
    EXPECT_DOUBLE_EQ(pace.target(1.0 / 15, kShare, 2.0), 1.0 / 15) << "nothing known yet";
    pace.note(0.1, 0.033, kShare);  // 10 Hz, the farm idle a third of it
    ASSERT_TRUE(pace.paced());
    EXPECT_DOUBLE_EQ(pace.target(1.0 / 15, kShare, 2.0), 0.085);
    EXPECT_DOUBLE_EQ(pace.target(0.1, kShare, 2.0), 0.1) << "never below the target";
    EXPECT_DOUBLE_EQ(pace.target(0.02, kShare, 2.0), 0.04) << "never above max_factor times it";
    // Following, the farm waits about the period's rest less the hand-off: it stays paced.
    for (int i = 0; i < 20; ++i) pace.note(0.1, 0.012, kShare);
    EXPECT_TRUE(pace.paced());
    EXPECT_NEAR(pace.period_s(), 0.1, 1e-12);
}

TEST(RequestPace, AnApplianceThatWaitsForTheFarmKeepsTheTarget) {
    RequestPace pace;
    for (int i = 0; i < 20; ++i) pace.note(0.07, 0.001, kShare);  // asks again once a frame is back
    EXPECT_FALSE(pace.paced());
    EXPECT_DOUBLE_EQ(pace.target(1.0 / 15, kShare, 2.0), 1.0 / 15);
    // Its wait grows (it slowed down): paced; it falls below a sixth of the rest: back to the target.
    for (int i = 0; i < 20; ++i) pace.note(0.1, 0.03, kShare);
    EXPECT_TRUE(pace.paced());
    for (int i = 0; i < 20; ++i) pace.note(0.1, 0.002, kShare);
    EXPECT_FALSE(pace.paced());
    pace.note(-1.0, 0.5, kShare);
    pace.note(0.0, 0.5, kShare);
    EXPECT_FALSE(pace.paced()) << "a request without a usable period changes nothing";
}

}  // namespace
}  // namespace mogao
