// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/session_budget.h"

#include <gtest/gtest.h>

#include "renderfarm/link/link_server.h"

namespace mogao {
namespace {

const LightCounts kRoom{1, 1, 1, true};  // the test room's lights: sun, point, area, environment

// The dear view admitted unchanged by the default request policy.
ViewRequest dear_view() {
    ViewRequest v;
    v.size = {320, 240};
    v.quality = {1, 8, 64, 64, 1.0, 85};
    return v;
}

ViewRequest ordinary_view() {
    ViewRequest v;
    v.size = {480, 270};
    return v;
}

TEST(SessionBudgets, PassesRequestsUntilAFrameWasMeasured) {
    SessionBudgets budgets({.frame_s = 1.0}, kRoom);
    const ViewRequest dear = dear_view();
    ASSERT_FALSE(apply_request_policy(dear, kRoom, RequestPolicy{}).degraded);  // admitted as asked
    const BudgetDecision d = budgets.apply(dear, "museum-2");
    EXPECT_FALSE(d.degraded);
    EXPECT_EQ(d.view.quality.ao_samples, 64);
}

// A dear frame measured at 8 s uncut: the appliance's next requests are degraded to about aim x
// budget at that rate; the ordinary appliance, measured cheap, is left alone.
TEST(SessionBudgets, DegradesTheNextRequestsOfADearApplianceToTheBudget) {
    SessionBudgets budgets({.frame_s = 1.0, .aim = 0.5}, kRoom);
    const ViewRequest dear = dear_view();
    budgets.observe("museum-2", dear, 8.0);
    budgets.observe("museum-1", ordinary_view(), 0.05);
    const BudgetDecision d = budgets.apply(dear, "museum-2");
    EXPECT_TRUE(d.degraded);
    EXPECT_FALSE(d.changes.empty());
    const double rate = budgets.rate("museum-2");
    EXPECT_NEAR(rate, estimated_rays(dear, kRoom) / 8.0, 1e-6 * rate);
    EXPECT_LE(estimated_rays(d.view, kRoom) / rate, 0.5 + 1e-9);
    EXPECT_NEAR(d.predicted_s, estimated_rays(d.view, kRoom) / rate, 1e-9);
    EXPECT_GT(d.predicted_s, 0.05);  // degraded to fit, not to nothing
    const BudgetDecision o = budgets.apply(ordinary_view(), "museum-1");
    EXPECT_FALSE(o.degraded);
}

// Frames of the degraded view measure within the band: the rate, and so the view, stay put (a still
// view keeps accumulating); a frame far outside the band replaces the rate.
TEST(SessionBudgets, KeepsItsRateWithinTheBandAndReplacesItOutside) {
    SessionBudgets budgets({.frame_s = 1.0, .aim = 0.5, .band = 2.0}, kRoom);
    const ViewRequest dear = dear_view();
    budgets.observe("museum-2", dear, 8.0);
    const double rate = budgets.rate("museum-2");
    const ViewRequest degraded = budgets.apply(dear, "museum-2").view;
    budgets.observe("museum-2", degraded, estimated_rays(degraded, kRoom) / (rate * 1.5));
    EXPECT_DOUBLE_EQ(budgets.rate("museum-2"), rate);
    EXPECT_EQ(budgets.apply(dear, "museum-2").view.quality.ao_samples, degraded.quality.ao_samples);
    budgets.observe("museum-2", degraded, estimated_rays(degraded, kRoom) / (rate * 10.0));  // a faster farm
    EXPECT_NEAR(budgets.rate("museum-2"), rate * 10.0, 1e-6 * rate);
}

// Other appliances waiting: a frame inside the budget but over its share of the farm is degraded
// to the share (aim x share at the measured rate); alone, the same request passes unchanged.
TEST(SessionBudgets, AShareOfTheFarmDegradesToTheShareButOnlyTheBudgetRefuses) {
    SessionBudgets budgets({.frame_s = 1.0, .aim = 0.5}, kRoom);
    const ViewRequest dear = dear_view();
    budgets.observe("museum-2", dear, 0.8);
    EXPECT_FALSE(budgets.apply(dear, "museum-2").degraded);
    const double rate = budgets.rate("museum-2");
    const BudgetDecision shared = budgets.apply(dear, "museum-2", 0.1);
    EXPECT_TRUE(shared.degraded);
    EXPECT_DOUBLE_EQ(shared.limit_s, 0.1);
    EXPECT_LE(estimated_rays(shared.view, kRoom) / rate, 0.5 * 0.1 + 1e-9);
    EXPECT_FALSE(budgets.apply(dear, "museum-2", 5.0).degraded);  // a share above the budget: the budget
    // A share no degradation reaches: degraded as far as it goes, and not refused (it fits the budget).
    const BudgetDecision tiny = budgets.apply(dear, "museum-2", 1e-9);
    EXPECT_TRUE(tiny.degraded);
    EXPECT_LE(tiny.predicted_s, 1.0);
}

// Two galleries sharing the farm: an ordinary view (1 spp, no bounces: nothing but pixels to lower)
// over its share is held at the frame-time controller's resolution floor, not shrunk to the share
// (the controller trades bounces below its floor; a served 184x91 frame was the result before).
// Held to the frame budget itself, the scale may still go below the floor.
TEST(SessionBudgets, AShareKeepsTheResolutionFloorTheBudgetDoesNot) {
    SessionBudgets budgets({.frame_s = 1.0, .aim = 0.5, .share_min_scale = 0.5}, kRoom);
    const ViewRequest view = ordinary_view();
    budgets.observe("museum-1", view, 0.4);  // its full-scale frame: 0.4 s
    const BudgetDecision shared = budgets.apply(view, "museum-1", 1.0 / 15.0);
    EXPECT_DOUBLE_EQ(shared.view.quality.resolution_scale, 0.5);
    SessionBudgets no_floor({.frame_s = 1.0, .aim = 0.5, .share_min_scale = 0.0}, kRoom);
    no_floor.observe("museum-1", view, 0.4);
    EXPECT_LT(no_floor.apply(view, "museum-1", 1.0 / 15.0).view.quality.resolution_scale, 0.3);  // as before
    // A view whose floor does not fit the budget: held to the budget, below the floor.
    budgets.observe("museum-1", view, 40.0);
    const BudgetDecision slow = budgets.apply(view, "museum-1", 1.0 / 15.0);
    EXPECT_DOUBLE_EQ(slow.limit_s, 1.0);
    EXPECT_LT(slow.view.quality.resolution_scale, 0.5);
    EXPECT_LE(slow.predicted_s, 1.0);
    // A request asking for less than the floor keeps its own scale.
    ViewRequest small = view;
    small.quality.resolution_scale = 0.3;
    budgets.observe("museum-3", small, 0.4);
    EXPECT_LE(budgets.apply(small, "museum-3", 1.0 / 15.0).view.quality.resolution_scale, 0.3);
}

TEST(SessionBudgets, RefusesWhatCannotFitEvenFullyDegradedWithTheReason) {
    SessionBudgets budgets({.frame_s = 1.0}, kRoom);
    const ViewRequest dear = dear_view();
    budgets.observe("museum-2", dear, 1e9);  // a farm far too slow for anything
    try {
        (void)budgets.apply(dear, "museum-2");
        FAIL() << "not refused";
    } catch (const RequestRefused& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("museum-2"), std::string::npos) << what;
        EXPECT_NE(what.find("frame budget of 1 s"), std::string::npos) << what;
    }
}

TEST(SessionBudgets, OffPassesEverythingAndBadSettingsAreRefused) {
    SessionBudgets off({.frame_s = 0.0}, kRoom);
    off.observe("museum-2", dear_view(), 100.0);
    EXPECT_FALSE(off.apply(dear_view(), "museum-2").degraded);
    EXPECT_THROW(SessionBudgets({.frame_s = -1.0}, kRoom), std::invalid_argument);
    EXPECT_THROW(SessionBudgets({.frame_s = 1.0, .aim = 0.0}, kRoom), std::invalid_argument);
    EXPECT_THROW(SessionBudgets({.frame_s = 1.0, .aim = 0.5, .band = 0.5}, kRoom), std::invalid_argument);
}

}  // namespace
}  // namespace mogao
