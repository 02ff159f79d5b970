// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/lab/code_ranking.h"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

#include "appliance/tracker/tag_bitmap.h"

namespace mogao {
namespace {

constexpr int kCellPx = 12;
constexpr int kOffset = 40;

// Tag `id` of tag36h11 printed upright at kCellPx per cell, its bitmap's top-left at
// (kOffset, kOffset), grey levels black..white, with Gaussian noise of `sigma` codes.
GrayImage printed_tag(const TagFamily& family, int id, double black, double white, double sigma) {
    const TagBitmap bitmap = make_tag_bitmap(family, id);
    GrayImage image(200, 200);
    std::mt19937 rng(3);
    std::normal_distribution<double> noise(0.0, sigma);
    for (int y = 0; y < image.height; ++y) {
        for (int x = 0; x < image.width; ++x) {
            const int cx = (x - kOffset) / kCellPx, cy = (y - kOffset) / kCellPx;
            const bool inside = x >= kOffset && y >= kOffset && cx < bitmap.cells && cy < bitmap.cells;
            const double v = inside ? (bitmap.at(cx, cy) == 255 ? white : black) : white;
            image.pixels[static_cast<std::size_t>(y * image.width + x)] =
                static_cast<std::uint8_t>(std::clamp(v + noise(rng), 0.0, 255.0));
        }
    }
    return image;
}

// The black square's corners in AprilTag order, pixel centres at +0.5 (pixel i spans [i, i + 1]).
TagCorners square_corners(const TagFamily& family) {
    const double lo = kOffset + kCellPx * (family.total_width_cells() - family.border_width_cells()) / 2.0;
    const double hi = lo + kCellPx * family.border_width_cells();
    return {Eigen::Vector2d(lo, hi), {hi, hi}, {hi, lo}, {lo, lo}};
}

TEST(CodeRanking, TheTrueCodeRanksFirstUnrotatedAndFarAboveChance) {
    const TagFamily family("tag36h11");
    const auto ranked = rank_codes(printed_tag(family, 42, 20.0, 200.0, 2.0), square_corners(family), family);
    ASSERT_EQ(ranked.size(), static_cast<std::size_t>(family.code_count()) * 8);
    EXPECT_EQ(ranked[0].id, 42);
    EXPECT_EQ(ranked[0].rotation, 0);
    EXPECT_FALSE(ranked[0].mirrored);
    EXPECT_GT(ranked[0].correlation, 0.95);
    EXPECT_LT(ranked[1].correlation, 0.8);  // tag36h11 codes differ in at least 11 of 36 cells
}

TEST(CodeRanking, ADarkLowContrastTagRanksLikeABrightOne) {
    const TagFamily family("tag36h11");
    const auto ranked = rank_codes(printed_tag(family, 87, 8.0, 24.0, 2.0), square_corners(family), family);
    EXPECT_EQ(ranked[0].id, 87);
    EXPECT_EQ(ranked[0].rotation, 0);
    EXPECT_GT(ranked[0].correlation, 0.85);
}

TEST(CodeRanking, CornersGivenFromAnotherSideShowAsARotation) {
    const TagFamily family("tag36h11");
    TagCorners c = square_corners(family);
    const TagCorners shifted{c[1], c[2], c[3], c[0]};
    const auto ranked = rank_codes(printed_tag(family, 42, 20.0, 200.0, 2.0), shifted, family);
    EXPECT_EQ(ranked[0].id, 42);
    EXPECT_NE(ranked[0].rotation, 0);
    EXPECT_FALSE(ranked[0].mirrored);
}

TEST(CodeRanking, RejectsBadCorners) {
    const TagFamily family("tag36h11");
    const GrayImage image = printed_tag(family, 1, 20.0, 200.0, 0.0);
    TagCorners tiny{Eigen::Vector2d(10, 12), {12, 12}, {12, 10}, {10, 10}};
    EXPECT_THROW((void)rank_codes(image, tiny, family), std::invalid_argument);
    TagCorners nan = square_corners(family);
    nan[2].x() = std::nan("");
    EXPECT_THROW((void)rank_codes(image, nan, family), std::invalid_argument);
    EXPECT_THROW((void)rank_codes(GrayImage{}, square_corners(family), family), std::invalid_argument);
}

}  // namespace
}  // namespace mogao
