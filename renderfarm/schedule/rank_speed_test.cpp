// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/schedule/rank_speed.h"

#include <stdexcept>

#include <gtest/gtest.h>

namespace mogao {
namespace {

TEST(RankSpeeds, UnobservedRankRunsAtFullSpeed) {
    const RankSpeeds s;
    EXPECT_DOUBLE_EQ(s.speed(0), 1.0);
    EXPECT_DOUBLE_EQ(s.speed(7), 1.0);
}

TEST(RankSpeeds, SharedCoreHalvesSpeedAndSmooths) {
    RankSpeeds s(0.5);
    s.observe(1, 0.5, 1.0);  // half a core
    EXPECT_DOUBLE_EQ(s.speed(1), 0.5);
    s.observe(1, 1.0, 1.0);  // then a core of its own: half way there
    EXPECT_DOUBLE_EQ(s.speed(1), 0.75);
    s.observe(1, 4.0, 2.0, 2);  // two threads, each with a core
    EXPECT_DOUBLE_EQ(s.speed(1), 0.875);
    EXPECT_DOUBLE_EQ(s.speed(0), 1.0);  // other ranks untouched
}

TEST(RankSpeeds, UntimeableFramesAndStarvationAreBounded) {
    RankSpeeds s;
    s.observe(0, 0.0, 0.0);  // ignored
    EXPECT_DOUBLE_EQ(s.speed(0), 1.0);
    s.observe(0, 0.0, 1.0);
    EXPECT_DOUBLE_EQ(s.speed(0), RankSpeeds::kMinSpeed);
    s.observe(2, 3.0, 1.0);  // clock skew: never above a core
    EXPECT_DOUBLE_EQ(s.speed(2), 1.0);
}

// The point of it: the same pixels on a rank that got half a core cost the same as on a rank
// with a core of its own, so the cost map built from both shows a flat image.
TEST(RankSpeeds, NormalisedTilesOfSharedRankMatchAnUnsharedRank) {
    const std::vector<TileTime> alone{{{0, 0, 16, 16}, 0.010}, {{16, 0, 32, 16}, 0.010}};
    const std::vector<TileTime> shared{{{32, 0, 48, 16}, 0.020}, {{48, 0, 64, 16}, 0.020}};
    RankSpeeds s;
    s.observe(0, 0.020, 0.020);
    s.observe(1, 0.020, 0.040);
    std::vector<TileTime> all = normalise_tile_times(alone, s.speed(0));
    const std::vector<TileTime> b = normalise_tile_times(shared, s.speed(1));
    all.insert(all.end(), b.begin(), b.end());
    const CostMap map = CostMap::from_tile_times({64, 16}, 16, all);
    for (int cx = 0; cx < 4; ++cx) EXPECT_NEAR(map.cell(cx, 0), 0.010, 1e-12) << cx;
}

TEST(RankSpeeds, RejectsBadArguments) {
    EXPECT_THROW(RankSpeeds(0.0), std::invalid_argument);
    RankSpeeds s;
    EXPECT_THROW(s.observe(-1, 1, 1), std::invalid_argument);
    EXPECT_THROW(s.observe(0, 1, 1, 0), std::invalid_argument);
    EXPECT_THROW((void)normalise_tile_times({}, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace mogao
