// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/schedule/cost_map.h"

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace mogao {
namespace {

// Random map whose cells hold values in [0, 1) per pixel times the cell's pixel count.
CostMap random_map(ImageSize size, int cell, unsigned seed) {
    CostMap map(size, cell);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int cy = 0; cy < map.cells_y(); ++cy) {
        for (int cx = 0; cx < map.cells_x(); ++cx) {
            map.set_cell(cx, cy, u(rng) * static_cast<double>(map.cell_rect(cx, cy).area()));
        }
    }
    return map;
}

// Reference: each pixel carries its cell's cost / cell pixel count.
double brute_sum(const CostMap& map, const PixelRect& r) {
    double s = 0.0;
    for (int y = r.y0; y < r.y1; ++y) {
        for (int x = r.x0; x < r.x1; ++x) {
            const int cx = x / map.cell_size();
            const int cy = y / map.cell_size();
            s += map.cell(cx, cy) / static_cast<double>(map.cell_rect(cx, cy).area());
        }
    }
    return s;
}

template <typename F>
std::string thrown_message(F&& f) {
    try {
        f();
    } catch (const std::invalid_argument& e) {
        return e.what();
    }
    return "<no std::invalid_argument>";
}

TEST(CostMap, GridCoversImageWithPartialLastCells) {
    const CostMap map({17, 5}, 16);
    EXPECT_EQ(map.cells_x(), 2);
    EXPECT_EQ(map.cells_y(), 1);
    EXPECT_EQ(map.cell_rect(1, 0), (PixelRect{16, 0, 17, 5}));
    EXPECT_EQ(map.total(), 0.0);
}

TEST(CostMap, UniformIsProportionalToPixelCount) {
    const CostMap map = CostMap::uniform({1000, 7}, 16, 2.0);
    EXPECT_EQ(map.cells_x(), 63);
    EXPECT_DOUBLE_EQ(map.cell(0, 0), 2.0 * 16 * 7);
    EXPECT_DOUBLE_EQ(map.cell(62, 0), 2.0 * 8 * 7);  // 1000 = 62*16 + 8
    EXPECT_DOUBLE_EQ(map.total(), 2.0 * 7000);
    EXPECT_DOUBLE_EQ(map.sum({5, 1, 37, 6}), 2.0 * 32 * 5);  // pro-rated: uniform density
}

TEST(CostMap, AlignedSumsMatchCellSums) {
    const CostMap map = random_map({1920, 1080}, 16, 7);
    std::mt19937 rng(3);
    for (int i = 0; i < 200; ++i) {
        std::uniform_int_distribution<int> cx(0, map.cells_x());
        std::uniform_int_distribution<int> cy(0, map.cells_y());
        int a = cx(rng), b = cx(rng), c = cy(rng), d = cy(rng);
        if (a > b) std::swap(a, b);
        if (c > d) std::swap(c, d);
        double expected = 0.0;
        for (int y = c; y < d; ++y) {
            for (int x = a; x < b; ++x) {
                expected += map.cell(x, y);
            }
        }
        const PixelRect r{a * 16, c * 16, std::min(b * 16, 1920), std::min(d * 16, 1080)};
        EXPECT_NEAR(map.sum(r), expected, 1e-9 * map.total()) << i;
    }
}

TEST(CostMap, UnalignedSumsAreProRatedByPixelArea) {
    const CostMap map = random_map({100, 37}, 16, 11);  // partial last column (4 px) and row (5 px)
    std::mt19937 rng(5);
    std::uniform_int_distribution<int> px(0, 100);
    std::uniform_int_distribution<int> py(0, 37);
    for (int i = 0; i < 300; ++i) {
        int a = px(rng), b = px(rng), c = py(rng), d = py(rng);
        if (a > b) std::swap(a, b);
        if (c > d) std::swap(c, d);
        const PixelRect r{a, c, b, d};
        EXPECT_NEAR(map.sum(r), brute_sum(map, r), 1e-9 * map.total()) << a << " " << b << " " << c << " " << d;
    }
}

TEST(CostMap, SumSeesCellsSetAfterAnEarlierSum) {
    CostMap map({64, 64}, 16);
    EXPECT_EQ(map.total(), 0.0);
    map.set_cell(3, 3, 2.5);
    EXPECT_DOUBLE_EQ(map.total(), 2.5);
    EXPECT_DOUBLE_EQ(map.sum({48, 48, 64, 64}), 2.5);
    EXPECT_DOUBLE_EQ(map.sum({48, 48, 56, 64}), 1.25);
    map.finalize();
    EXPECT_DOUBLE_EQ(map.sum({0, 0, 48, 64}), 0.0);
}

TEST(CostMap, EmptyRectsCostNothingAnywhere) {
    const CostMap map = CostMap::uniform({32, 32}, 16);
    EXPECT_EQ(map.sum({10, 10, 10, 20}), 0.0);
    EXPECT_EQ(map.sum({500, 500, 400, 400}), 0.0);
}

TEST(CostMap, FromTileTimesConservesTotalTime) {
    const ImageSize size{1920, 1080};
    std::vector<TileTime> tiles;
    std::mt19937 rng(9);
    std::exponential_distribution<double> seconds(100.0);
    double expected = 0.0;
    for (int y = 0; y < size.height; y += 64) {
        for (int x = 0; x < size.width; x += 48) {
            tiles.push_back({{x, y, std::min(x + 48, size.width), std::min(y + 64, size.height)}, seconds(rng)});
            expected += tiles.back().seconds;
        }
    }
    const CostMap map = CostMap::from_tile_times(size, 16, tiles);
    EXPECT_NEAR(map.total(), expected, 1e-12 * expected);
    for (const TileTime& t : tiles) {
        EXPECT_NEAR(map.sum(t.rect), t.seconds, 1e-9 * expected);
    }
}

TEST(CostMap, FromTileTimesSpreadsByPixelCount) {
    // A 24x16 tile over cells (0,0) (16 px wide) and (1,0) (8 px of it): 2/3 and 1/3 of its time.
    const std::vector<TileTime> tiles{{{0, 0, 24, 16}, 3.0}, {{24, 0, 32, 16}, 0.5}, {{0, 16, 1, 17}, 0.0}};
    const CostMap map = CostMap::from_tile_times({40, 20}, 16, tiles);
    EXPECT_DOUBLE_EQ(map.cell(0, 0), 2.0);
    EXPECT_DOUBLE_EQ(map.cell(1, 0), 1.5);
    EXPECT_DOUBLE_EQ(map.cell(2, 0), 0.0);
    EXPECT_DOUBLE_EQ(map.total(), 3.5);
}

TEST(CostMap, BadInputsNameTheFieldAndLimit) {
    EXPECT_NE(thrown_message([] { CostMap m({10, 10}, 0); }).find("cell_size must be >= 1"), std::string::npos);
    EXPECT_NE(thrown_message([] { CostMap m({-1, 10}, 16); }).find("width and height must be >= 0"), std::string::npos);
    CostMap map({32, 32}, 16);
    EXPECT_NE(thrown_message([&] { map.set_cell(0, 0, -1.0); }).find(">= 0"), std::string::npos);
    EXPECT_THROW(map.set_cell(0, 0, std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
    EXPECT_THROW(map.set_cell(0, 0, std::numeric_limits<double>::infinity()), std::invalid_argument);
    EXPECT_NE(thrown_message([&] { (void)map.cell(2, 0); }).find("cx must be in [0,2)"), std::string::npos);
    EXPECT_THROW((void)map.cell(0, -1), std::invalid_argument);
    EXPECT_NE(thrown_message([&] { (void)map.sum({0, 0, 33, 8}); }).find("outside the image"), std::string::npos);
    EXPECT_THROW((void)map.sum({-1, 0, 3, 8}), std::invalid_argument);
    EXPECT_THROW((void)CostMap::uniform({8, 8}, 16, -1.0), std::invalid_argument);

    const auto from = [](TileTime t) { return CostMap::from_tile_times({32, 32}, 16, std::vector<TileTime>{t}); };
    EXPECT_NE(thrown_message([&] { from({{0, 0, 16, 16}, -0.1}); }).find("TileTime.seconds"), std::string::npos);
    EXPECT_THROW(from({{0, 0, 16, 16}, std::numeric_limits<double>::quiet_NaN()}), std::invalid_argument);
    EXPECT_NE(thrown_message([&] { from({{16, 16, 48, 32}, 1.0}); }).find("outside the image"), std::string::npos);
    EXPECT_NE(thrown_message([&] { from({{4, 4, 4, 8}, 1.0}); }).find("is empty"), std::string::npos);
    EXPECT_NO_THROW(from({{4, 4, 4, 8}, 0.0}));
    EXPECT_THROW((void)CostMap::from_tile_times({32, 32}, 0, {}), std::invalid_argument);
}

TEST(CostMap, ResampledKeepsWhereTheCostIs) {
    // 64x32, left half ten times dearer than the right; the same view at half and at 1.5x size.
    CostMap map({64, 32}, 16);
    for (int cy = 0; cy < 2; ++cy)
        for (int cx = 0; cx < 4; ++cx) map.set_cell(cx, cy, cx < 2 ? 10.0 : 1.0);
    const CostMap half = map.resampled({32, 16}, 16);
    ASSERT_EQ(half.cells_x(), 2);
    EXPECT_NEAR(half.cell(0, 0), 40.0, 1e-9);  // the whole left half of the old map
    EXPECT_NEAR(half.cell(1, 0), 4.0, 1e-9);
    EXPECT_NEAR(half.total(), map.total(), 1e-9);
    const CostMap larger = map.resampled({96, 48}, 16);
    EXPECT_NEAR(larger.total(), map.total(), 1e-6);
    EXPECT_GT(larger.sum({0, 0, 48, 48}), 9.0 * larger.sum({48, 0, 96, 48}));
    EXPECT_EQ(CostMap({0, 0}, 16).resampled({8, 8}, 16).total(), 0.0);
}

}  // namespace
}  // namespace mogao
