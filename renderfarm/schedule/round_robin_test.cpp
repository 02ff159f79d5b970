// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/schedule/round_robin.h"

#include <stdexcept>

#include <gtest/gtest.h>

namespace mogao {
namespace {

TEST(RoundRobinBalancer, DealsTilesInScanlineOrder) {
    // 100x40 with 32 px tiles: 4 columns (last 4 px wide) x 2 rows (last 8 px high) = 8 tiles.
    const Assignment a = RoundRobinBalancer(32).assign(CostMap::uniform({100, 40}), 3);
    ASSERT_EQ(a.rects.size(), 3u);
    const std::vector<PixelRect> rank0{{0, 0, 32, 32}, {96, 0, 100, 32}, {64, 32, 96, 40}};
    const std::vector<PixelRect> rank1{{32, 0, 64, 32}, {0, 32, 32, 40}, {96, 32, 100, 40}};
    const std::vector<PixelRect> rank2{{64, 0, 96, 32}, {32, 32, 64, 40}};
    EXPECT_EQ(a.rects[0], rank0);
    EXPECT_EQ(a.rects[1], rank1);
    EXPECT_EQ(a.rects[2], rank2);
    EXPECT_DOUBLE_EQ(a.predicted_cost[2], 32.0 * 32 + 32 * 8);
}

TEST(RoundRobinBalancer, RanksBeyondTheTileCountGetNothing) {
    const Assignment a = RoundRobinBalancer(32).assign(CostMap::uniform({40, 20}), 5);
    ASSERT_EQ(a.rects.size(), 5u);
    EXPECT_EQ(a.rects[0].size(), 1u);
    EXPECT_EQ(a.rects[1].size(), 1u);
    for (int r = 2; r < 5; ++r) {
        EXPECT_TRUE(a.rects[static_cast<std::size_t>(r)].empty());
        EXPECT_EQ(a.predicted_cost[static_cast<std::size_t>(r)], 0.0);
    }
}

TEST(RoundRobinBalancer, RejectsTileBelowOnePixel) {
    EXPECT_THROW(RoundRobinBalancer(0), std::invalid_argument);
    EXPECT_EQ(RoundRobinBalancer().tile(), 32);
}

}  // namespace
}  // namespace mogao
