// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/schedule/balance_efficiency.h"

#include <stdexcept>

#include <gtest/gtest.h>

namespace mogao {
namespace {

// 48x16 image, three 16x16 cells costing 1, 2 and 3 seconds.
CostMap three_cells() {
    CostMap map({48, 16}, 16);
    map.set_cell(0, 0, 1.0);
    map.set_cell(1, 0, 2.0);
    map.set_cell(2, 0, 3.0);
    return map;
}

Assignment one_cell_per_rank() { return {{{{0, 0, 16, 16}}, {{16, 0, 32, 16}}, {{32, 0, 48, 16}}}, {0.0, 0.0, 0.0}}; }

TEST(BalanceEfficiency, MeanOverMax) {
    EXPECT_DOUBLE_EQ(balance_efficiency(one_cell_per_rank(), three_cells()), 2.0 / 3.0);
}

TEST(BalanceEfficiency, PerfectBalanceIsOne) {
    const Assignment a{{{{0, 0, 32, 16}}, {{32, 0, 48, 16}}}, {0.0, 0.0}};
    EXPECT_DOUBLE_EQ(balance_efficiency(a, three_cells()), 1.0);
}

TEST(BalanceEfficiency, OneRankDoingEverythingIsOneOverRanks) {
    const Assignment a{{{{0, 0, 48, 16}}, {}, {{0, 0, 0, 0}}, {}}, {0.0, 0.0, 0.0, 0.0}};
    EXPECT_DOUBLE_EQ(balance_efficiency(a, three_cells()), 0.25);
}

TEST(BalanceEfficiency, UsesTheActualMapNotThePrediction) {
    Assignment a = one_cell_per_rank();
    a.predicted_cost = {2.0, 2.0, 2.0};  // a perfect prediction does not make a perfect frame
    EXPECT_LT(balance_efficiency(a, three_cells()), 0.7);
}

TEST(BalanceEfficiency, NoWorkAtAllIsPerfect) {
    EXPECT_DOUBLE_EQ(balance_efficiency(one_cell_per_rank(), CostMap({48, 16}, 16)), 1.0);
}

TEST(BalanceEfficiency, RejectsZeroRanksAndForeignRects) {
    EXPECT_THROW((void)balance_efficiency(Assignment{}, three_cells()), std::invalid_argument);
    const Assignment outside{{{{0, 0, 64, 16}}}, {0.0}};
    EXPECT_THROW((void)balance_efficiency(outside, three_cells()), std::invalid_argument);
}

}  // namespace
}  // namespace mogao
