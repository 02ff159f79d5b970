// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/schedule/load_balancer.h"

#include <random>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "renderfarm/schedule/schedule_test_util.h"

namespace mogao {
namespace {

CostMap random_map(ImageSize size, unsigned seed) {
    CostMap map(size, 16);
    std::mt19937 rng(seed);
    std::exponential_distribution<double> u(1.0);
    for (int cy = 0; cy < map.cells_y(); ++cy) {
        for (int cx = 0; cx < map.cells_x(); ++cx) {
            map.set_cell(cx, cy, u(rng));
        }
    }
    return map;
}

TEST(LoadBalancer, EveryBalancerTilesTheImageExactlyOnce) {
    for (const ImageSize size : {ImageSize{1920, 1080}, ImageSize{1000, 7}, ImageSize{17, 5}, ImageSize{1, 1},
                                 ImageSize{0, 0}, ImageSize{33, 300}}) {
        const CostMap map = random_map(size, 42);
        for (const auto name : load_balancer_names()) {
            for (const int snap_or_tile : {8, 16, 32}) {
                const auto balancer = make_load_balancer(name, snap_or_tile);
                EXPECT_EQ(balancer->name(), name);
                for (int ranks = 1; ranks <= 17; ++ranks) {
                    SCOPED_TRACE(std::string(name) + " " + std::to_string(size.width) + "x" +
                                 std::to_string(size.height) + " snap/tile " + std::to_string(snap_or_tile) +
                                 " ranks " + std::to_string(ranks));
                    const Assignment a = balancer->assign(map, ranks);
                    test::expect_tiles_image_exactly_once(a, size, ranks);
                    // predicted_cost is the given map's cost of each rank's rects.
                    double total = 0.0;
                    for (std::size_t r = 0; r < a.rects.size(); ++r) {
                        double expected = 0.0;
                        for (const PixelRect& rect : a.rects[r]) {
                            expected += map.sum(rect);
                        }
                        EXPECT_NEAR(a.predicted_cost[r], expected, 1e-9 * (1.0 + expected));
                        total += a.predicted_cost[r];
                    }
                    EXPECT_NEAR(total, map.total(), 1e-9 * (1.0 + total));
                }
            }
        }
    }
}

TEST(LoadBalancer, FactoryRejectsUnknownNamesListingTheValidOnes) {
    try {
        (void)make_load_balancer("kd", 16);
        FAIL() << "no exception";
    } catch (const std::invalid_argument& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("pbt, equal, roundrobin"), std::string::npos) << msg;
        EXPECT_NE(msg.find("\"kd\""), std::string::npos) << msg;
    }
    EXPECT_THROW((void)make_load_balancer("PBT", 16), std::invalid_argument);
    EXPECT_THROW((void)make_load_balancer("pbt", 0), std::invalid_argument);
    EXPECT_THROW((void)make_load_balancer("roundrobin", -1), std::invalid_argument);
}

TEST(LoadBalancer, RankCountsOutsideTheLimitAreRejected) {
    const CostMap map = CostMap::uniform({64, 64});
    for (const auto name : load_balancer_names()) {
        const auto balancer = make_load_balancer(name, 16);
        EXPECT_THROW((void)balancer->assign(map, 0), std::invalid_argument) << name;
        EXPECT_THROW((void)balancer->assign(map, -3), std::invalid_argument) << name;
        EXPECT_THROW((void)balancer->assign(map, LoadBalancer::kMaxRanks + 1), std::invalid_argument) << name;
    }
}

}  // namespace
}  // namespace mogao
