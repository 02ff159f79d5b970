// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/schedule/balance_sim.h"

#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "renderfarm/schedule/balance_efficiency.h"
#include "renderfarm/schedule/pbt.h"

namespace mogao {
namespace {

TEST(BalanceSim, PbtBeatsEqualSplitOnASlowlyMovingHotSpot) {
    MovingHotspot spec;
    spec.image = {960, 540};
    spec.frames = 12;
    spec.sigma_px = 60.0;
    spec.speed_px_per_frame = 4.0;
    const std::vector<CostMap> frames = moving_hotspot_frames(spec);
    const auto results = simulate_balance(frames, BalanceSimOptions{});
    ASSERT_EQ(results.size(), 9u);  // {4, 8, 16} x {pbt, equal, roundrobin}
    for (std::size_t i = 0; i < results.size(); i += 3) {
        const BalanceSimResult& pbt = results[i];
        const BalanceSimResult& equal = results[i + 1];
        ASSERT_EQ(pbt.balancer, "pbt");
        ASSERT_EQ(equal.balancer, "equal");
        ASSERT_EQ(results[i + 2].balancer, "roundrobin");
        ASSERT_EQ(pbt.ranks, equal.ranks);
        ASSERT_EQ(pbt.efficiency.size(), 12u);
        // Frame 0 predicts with the uniform map, so PBT and equal split coincide there.
        EXPECT_DOUBLE_EQ(pbt.efficiency[0], equal.efficiency[0]) << pbt.ranks;
        EXPECT_GT(pbt.mean_efficiency, equal.mean_efficiency + 0.1) << pbt.ranks;
        EXPECT_GT(pbt.min_efficiency, 0.0);
        EXPECT_LE(pbt.mean_efficiency, 1.0);
        EXPECT_DOUBLE_EQ(pbt.mean_rects_per_rank, 1.0);  // one non-empty leaf per rank here
    }
}

TEST(BalanceSim, FrameFIsPredictedFromFrameFMinusOne) {
    MovingHotspot spec;
    spec.image = {640, 360};
    spec.frames = 3;
    spec.speed_px_per_frame = 150.0;  // fast: prediction and actual differ a lot
    const std::vector<CostMap> frames = moving_hotspot_frames(spec);
    BalanceSimOptions options;
    options.rank_counts = {5};
    options.balancers = {"pbt"};
    const auto results = simulate_balance(frames, options);
    ASSERT_EQ(results.size(), 1u);
    const PbtBalancer pbt(16);
    EXPECT_DOUBLE_EQ(results[0].efficiency[0],
                     balance_efficiency(pbt.assign(CostMap::uniform(spec.image), 5), frames[0]));
    EXPECT_DOUBLE_EQ(results[0].efficiency[2], balance_efficiency(pbt.assign(frames[1], 5), frames[2]));
}

TEST(BalanceSim, MarkdownTableHasEfficienciesAndRatios) {
    BalanceSimResult pbt{"pbt", 4, {0.9, 0.8}, 0.85, 0.8, 1.0};
    BalanceSimResult equal{"equal", 4, {0.5, 0.35}, 0.425, 0.35, 1.0};
    const std::vector<BalanceSimResult> results{pbt, equal};
    const std::string table = balance_table_markdown(results);
    EXPECT_NE(table.find("| 4 | pbt | 2 | 0.850 | 0.800 | 1.0 |"), std::string::npos) << table;
    EXPECT_NE(table.find("| 4 | 2.000 | n/a |"), std::string::npos) << table;
}

TEST(BalanceSim, RejectsEmptyOrMismatchedSequences) {
    EXPECT_THROW((void)simulate_balance({}, BalanceSimOptions{}), std::invalid_argument);
    const std::vector<CostMap> mixed{CostMap::uniform({64, 64}), CostMap::uniform({64, 32})};
    EXPECT_THROW((void)simulate_balance(mixed, BalanceSimOptions{}), std::invalid_argument);
    const std::vector<CostMap> one{CostMap::uniform({64, 64})};
    BalanceSimOptions bad;
    bad.balancers = {"pbt", "nope"};
    EXPECT_THROW((void)simulate_balance(one, bad), std::invalid_argument);
    bad = {};
    bad.rank_counts = {4, 0};
    EXPECT_THROW((void)simulate_balance(one, bad), std::invalid_argument);
}

}  // namespace
}  // namespace mogao
