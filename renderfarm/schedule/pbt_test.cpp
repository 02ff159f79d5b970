// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/schedule/pbt.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "renderfarm/schedule/schedule_test_util.h"

namespace mogao {
namespace {

// Fills each cell with density(cell centre) * cell pixel count.
CostMap map_from_density(ImageSize size, int cell, const std::function<double(double, double)>& density) {
    CostMap map(size, cell);
    for (int cy = 0; cy < map.cells_y(); ++cy) {
        for (int cx = 0; cx < map.cells_x(); ++cx) {
            const PixelRect r = map.cell_rect(cx, cy);
            map.set_cell(cx, cy, density((r.x0 + r.x1) / 2.0, (r.y0 + r.y1) / 2.0) * static_cast<double>(r.area()));
        }
    }
    return map;
}

struct NamedMap {
    std::string name;
    CostMap map;
};

std::vector<NamedMap> synthetic_maps(ImageSize size) {
    std::vector<NamedMap> maps;
    maps.push_back({"gradient", map_from_density(size, 16, [&](double x, double y) {
                        return 1.0 + 9.0 * x / size.width + 3.0 * y / size.height;
                    })});
    maps.push_back({"hot block", map_from_density(size, 16, [&](double x, double y) {
                        const bool hot = x > 0.3 * size.width && x < 0.45 * size.width && y > 0.2 * size.height &&
                                         y < 0.5 * size.height;
                        return hot ? 50.0 : 1.0;
                    })});
    std::mt19937 rng(1234);
    std::lognormal_distribution<double> noise(0.0, 1.5);
    maps.push_back({"random", map_from_density(size, 16, [&](double, double) { return noise(rng); })});
    return maps;
}

// Low/high cut positions a node could use: its edges and the multiples of snap strictly inside.
std::vector<int> candidates(int lo, int hi, int snap) {
    std::vector<int> c{lo};
    for (int p = (lo / snap + 1) * snap; p < hi; p += snap) {
        c.push_back(p);
    }
    if (hi > lo) {
        c.push_back(hi);
    }
    return c;
}

PixelRect low_of(const PbtNode& n, int p) {
    return n.axis == SplitAxis::x ? PixelRect{n.rect.x0, n.rect.y0, p, n.rect.y1}
                                  : PixelRect{n.rect.x0, n.rect.y0, n.rect.x1, p};
}

// Cost of the snap-wide strip [p_a, p_b) across the node that contains the ideal cut (p_a: last
// candidate whose low side costs <= the ideal). This is the per-node bound documented in pbt.h.
double straddling_strip_cost(const CostMap& map, const PbtNode& n, int snap) {
    if (n.area_fallback) {
        return n.predicted_cost;  // ~0: every child of a zero-cost node is within it of the ideal
    }
    const int lo = n.axis == SplitAxis::x ? n.rect.x0 : n.rect.y0;
    const int hi = n.axis == SplitAxis::x ? n.rect.x1 : n.rect.y1;
    const double ideal = n.predicted_cost * (n.leaves / 2) / n.leaves;
    const auto c = candidates(lo, hi, snap);
    std::size_t a = 0;
    for (std::size_t i = 0; i < c.size(); ++i) {
        if (map.sum(low_of(n, c[i])) <= ideal) {
            a = i;
        }
    }
    const std::size_t b = std::min(a + 1, c.size() - 1);
    return map.sum(low_of(n, c[b])) - map.sum(low_of(n, c[a]));
}

void expect_tree_invariants(const CostMap& map, const PredictionBinaryTree& tree, const std::string& what) {
    const auto& nodes = tree.nodes();
    const double eps = 1e-9 * std::max(1.0, map.total());
    const ImageSize size = map.size();
    ASSERT_EQ(nodes.size(), 2 * static_cast<std::size_t>(tree.ranks()) - 1) << what;
    EXPECT_EQ(nodes[0].rect, PixelRect::whole(size)) << what;
    // Leaf bound: accumulated straddling-strip costs of the ancestors, walked from the root.
    std::vector<double> bound(nodes.size(), 0.0);
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        const PbtNode& n = nodes[i];
        if (n.axis == SplitAxis::none) {
            EXPECT_EQ(n.leaves, 1) << what;
            EXPECT_EQ(&tree.leaf(n.first_rank), &n) << what << ": leaf numbering";
            const double ideal = map.total() / tree.ranks();
            EXPECT_LE(std::abs(n.predicted_cost - ideal), bound[i] + eps) << what << " leaf rank " << n.first_rank;
            continue;
        }
        const PbtNode& low = nodes[static_cast<std::size_t>(n.children[0])];
        const PbtNode& high = nodes[static_cast<std::size_t>(n.children[1])];
        EXPECT_EQ(low.leaves, n.leaves / 2) << what;
        EXPECT_EQ(high.leaves, n.leaves - n.leaves / 2) << what;
        EXPECT_EQ(high.first_rank, n.first_rank + low.leaves) << what;
        // Children partition the node at the split.
        const bool x = n.axis == SplitAxis::x;
        const int lo = x ? n.rect.x0 : n.rect.y0;
        const int hi = x ? n.rect.x1 : n.rect.y1;
        ASSERT_TRUE(n.split >= lo && n.split <= hi) << what;
        EXPECT_EQ(low.rect, low_of(n, n.split)) << what;
        EXPECT_EQ(high.rect, (x ? PixelRect{n.split, n.rect.y0, n.rect.x1, n.rect.y1}
                                : PixelRect{n.rect.x0, n.split, n.rect.x1, n.rect.y1}))
            << what;
        // Snapping: multiple of snap in absolute coordinates, or the image border.
        const int border = x ? size.width : size.height;
        EXPECT_TRUE(n.split % tree.snap() == 0 || n.split == border) << what << ": split " << n.split;
        // Per-node bound.
        const double strip = straddling_strip_cost(map, n, tree.snap());
        const double ideal_low = n.predicted_cost * low.leaves / n.leaves;
        EXPECT_LE(std::abs(low.predicted_cost - ideal_low), strip + eps) << what << ": node " << i;
        EXPECT_NEAR(low.predicted_cost + high.predicted_cost, n.predicted_cost, eps) << what;
        bound[static_cast<std::size_t>(n.children[0])] = bound[i] + strip;
        bound[static_cast<std::size_t>(n.children[1])] = bound[i] + strip;
        // Optimality among the candidates of the chosen axis.
        if (!n.area_fallback) {
            double best = 1e300;
            for (const int p : candidates(lo, hi, tree.snap())) {
                const double l = map.sum(low_of(n, p));
                best = std::min(best, std::max(l / low.leaves, (n.predicted_cost - l) / high.leaves));
            }
            const double chosen = std::max(low.predicted_cost / low.leaves, high.predicted_cost / high.leaves);
            EXPECT_LE(chosen, best + eps) << what << ": node " << i;
        }
    }
}

TEST(PredictionBinaryTree, SyntheticMapsBalanceWithinOneSnapStrip) {
    for (const ImageSize size : {ImageSize{1920, 1080}, ImageSize{1000, 7}, ImageSize{17, 5}, ImageSize{333, 999}}) {
        for (const auto& [name, map] : synthetic_maps(size)) {
            for (const int snap : {8, 16}) {
                for (int ranks = 1; ranks <= 17; ++ranks) {
                    const PredictionBinaryTree tree(map, ranks, snap);
                    expect_tree_invariants(map, tree,
                                           name + " " + std::to_string(size.width) + "x" + std::to_string(size.height) +
                                               " snap " + std::to_string(snap) + " ranks " + std::to_string(ranks));
                }
            }
        }
    }
}

TEST(PredictionBinaryTree, CutsAlongTheLongerSide) {
    const PredictionBinaryTree wide(CostMap::uniform({1920, 1080}), 2, 16);
    EXPECT_EQ(wide.nodes()[0].axis, SplitAxis::x);
    EXPECT_EQ(wide.nodes()[0].split, 960);
    const PredictionBinaryTree tall(CostMap::uniform({100, 384}), 2, 16);
    EXPECT_EQ(tall.nodes()[0].axis, SplitAxis::y);
    EXPECT_EQ(tall.nodes()[0].split, 192);
}

TEST(PredictionBinaryTree, OddLeafCountsGetProportionalTargets) {
    // 3 ranks on a uniform 960-wide map: the low child (1 leaf) should get a third, 320 px.
    const PredictionBinaryTree tree(CostMap::uniform({960, 100}), 3, 16);
    EXPECT_EQ(tree.nodes()[0].split, 320);
    EXPECT_EQ(tree.leaf(0).rect, (PixelRect{0, 0, 320, 100}));
}

TEST(PredictionBinaryTree, HotSpotGetsSmallerLeaves) {
    // Left half costs 9x the right half per pixel: with 2 ranks the cut moves left of the middle.
    CostMap map({1024, 512}, 16);
    for (int cy = 0; cy < map.cells_y(); ++cy) {
        for (int cx = 0; cx < map.cells_x(); ++cx) {
            map.set_cell(cx, cy, cx < 32 ? 9.0 : 1.0);
        }
    }
    const PredictionBinaryTree tree(map, 2, 16);
    // Total 32*32*10 = 10240, half = 5120 = 9 * 16 * 32 + ... -> x = 16 * (5120 / 288) ~ 284.4 -> 288.
    EXPECT_EQ(tree.nodes()[0].split, 288);
}

TEST(PredictionBinaryTree, OneRankIsTheWholeImage) {
    const PredictionBinaryTree tree(CostMap::uniform({1920, 1080}), 1, 16);
    ASSERT_EQ(tree.nodes().size(), 1u);
    EXPECT_EQ(tree.leaf(0).rect, (PixelRect{0, 0, 1920, 1080}));
    EXPECT_EQ(tree.leaf(0).axis, SplitAxis::none);
}

Assignment assignment_of(const PredictionBinaryTree& tree) {
    Assignment a;
    for (const PixelRect& r : tree.leaf_rects()) {
        a.rects.push_back({r});
        a.predicted_cost.push_back(0.0);
    }
    return a;
}

TEST(PredictionBinaryTree, MoreRanksThanSnappedColumnsStillTilesTheImage) {
    const CostMap map = CostMap::uniform({17, 5});
    const PredictionBinaryTree tree(map, 17, 16);
    test::expect_tiles_image_exactly_once(assignment_of(tree), map.size(), 17);
    for (const PbtNode& n : tree.nodes()) {
        if (n.axis == SplitAxis::x) {
            EXPECT_TRUE(n.split == 0 || n.split == 16 || n.split == 17) << n.split;
        } else if (n.axis == SplitAxis::y) {
            EXPECT_TRUE(n.split == 0 || n.split == 5) << n.split;
        }
    }
    int non_empty = 0;
    for (const PixelRect& r : tree.leaf_rects()) {
        non_empty += r.empty() ? 0 : 1;
    }
    EXPECT_EQ(non_empty, 2);  // only [0,16) and [16,17) exist as snapped columns
}

TEST(PredictionBinaryTree, ImageSmallerThanSnapGoesToOneLeaf) {
    const CostMap map = CostMap::uniform({5, 3});
    const PredictionBinaryTree tree(map, 4, 16);
    test::expect_tiles_image_exactly_once(assignment_of(tree), map.size(), 4);
    int whole = 0;
    for (const PixelRect& r : tree.leaf_rects()) {
        EXPECT_TRUE(r.empty() || r == PixelRect::whole(map.size()));
        whole += r.empty() ? 0 : 1;
    }
    EXPECT_EQ(whole, 1);
}

TEST(PredictionBinaryTree, AllZeroCostsFallBackToArea) {
    const CostMap zero({1920, 1080}, 16);
    const PredictionBinaryTree tree(zero, 8, 16);
    const PredictionBinaryTree area(CostMap::uniform({1920, 1080}), 8, 16);
    EXPECT_EQ(tree.leaf_rects(), area.leaf_rects());
    EXPECT_TRUE(tree.nodes()[0].area_fallback);
    for (const PixelRect& r : tree.leaf_rects()) {
        EXPECT_NEAR(static_cast<double>(r.area()), 1920.0 * 1080 / 8, 16.0 * 1080);
    }
}

TEST(PredictionBinaryTree, OneHotPixelSpreadsTheColdRegionByArea) {
    const ImageSize size{1920, 1080};
    const std::vector<TileTime> tiles{{{1000, 500, 1001, 501}, 1.0}};
    const CostMap map = CostMap::from_tile_times(size, 16, tiles);
    for (int ranks = 1; ranks <= 17; ++ranks) {
        const PredictionBinaryTree tree(map, ranks, 16);
        test::expect_tiles_image_exactly_once(assignment_of(tree), size, ranks);
        expect_tree_invariants(map, tree, "hot pixel, ranks " + std::to_string(ranks));
        int hot = 0;
        for (int r = 0; r < ranks; ++r) {
            hot += tree.leaf(r).predicted_cost > 0.5 ? 1 : 0;
        }
        EXPECT_EQ(hot, 1) << ranks;
        if (ranks == 1) {
            continue;
        }
        // The root's cold child has zero cost: it is split by area, so none of its ranks idles.
        const auto& root = tree.nodes()[0];
        const bool hot_low = tree.nodes()[static_cast<std::size_t>(root.children[0])].rect.contains(1000, 500);
        const PbtNode& cold = tree.nodes()[static_cast<std::size_t>(root.children[hot_low ? 1 : 0])];
        EXPECT_TRUE(cold.area_fallback || cold.leaves == 1) << ranks;
        for (int r = cold.first_rank; r < cold.first_rank + cold.leaves; ++r) {
            EXPECT_FALSE(tree.leaf(r).rect.empty()) << "ranks " << ranks << " rank " << r;
        }
        // Regression guard: up to 16 ranks no rank is idle at all. (With 17, a 3-leaf node whose cost
        // is one pixel in its first snap column legitimately gives its low leaf an empty rect: that
        // minimises the predicted cost per leaf, see pbt.h.)
        for (int r = 0; ranks <= 16 && r < ranks; ++r) {
            EXPECT_FALSE(tree.leaf(r).rect.empty()) << "ranks " << ranks << " rank " << r;
        }
    }
}

TEST(PredictionBinaryTree, BadArguments) {
    const CostMap map = CostMap::uniform({64, 64});
    EXPECT_THROW(PredictionBinaryTree(map, 0, 16), std::invalid_argument);
    EXPECT_THROW(PredictionBinaryTree(map, LoadBalancer::kMaxRanks + 1, 16), std::invalid_argument);
    EXPECT_THROW(PredictionBinaryTree(map, 2, 0), std::invalid_argument);
    EXPECT_THROW(PbtBalancer(0), std::invalid_argument);
    EXPECT_THROW(EqualSplitBalancer(-8), std::invalid_argument);
    const PredictionBinaryTree tree(map, 2, 16);
    EXPECT_THROW((void)tree.leaf(2), std::invalid_argument);
}

TEST(EqualSplitBalancer, IgnoresTheMeasuredCosts) {
    const ImageSize size{1920, 1080};
    const auto maps = synthetic_maps(size);
    const EqualSplitBalancer equal(16);
    const Assignment on_uniform = equal.assign(CostMap::uniform(size), 7);
    const Assignment on_hot = equal.assign(maps[1].map, 7);
    EXPECT_EQ(on_hot.rects, on_uniform.rects);
    // The reported prediction still comes from the map it was given.
    double sum = 0.0;
    for (const double c : on_hot.predicted_cost) {
        sum += c;
    }
    EXPECT_NEAR(sum, maps[1].map.total(), 1e-9 * sum);
}

TEST(PbtBalancer, PredictsBetterBalanceThanEqualSplitOnAHotBlock) {
    const auto maps = synthetic_maps({1920, 1080});
    const CostMap& hot = maps[1].map;
    for (const int ranks : {4, 8, 16}) {
        const Assignment pbt = PbtBalancer(16).assign(hot, ranks);
        const Assignment equal = EqualSplitBalancer(16).assign(hot, ranks);
        const double pbt_max = *std::max_element(pbt.predicted_cost.begin(), pbt.predicted_cost.end());
        const double equal_max = *std::max_element(equal.predicted_cost.begin(), equal.predicted_cost.end());
        EXPECT_LT(pbt_max, 0.8 * equal_max) << ranks;
        EXPECT_LT(pbt_max, 1.2 * hot.total() / ranks) << ranks;
    }
}

}  // namespace
}  // namespace mogao
