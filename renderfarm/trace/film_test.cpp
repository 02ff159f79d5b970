// SPDX-License-Identifier: Apache-2.0
#include <cmath>
#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

#include "renderfarm/trace/film.h"

namespace mogao {
namespace {

// Reference: the IEC 61966-2-1 OETF evaluated directly.
int reference_code(double v) {
    v = std::clamp(v, 0.0, 1.0);
    const double e = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
    return static_cast<int>(std::lround(255.0 * e));
}

TEST(Film, KnownSrgbCodes) {
    EXPECT_EQ(encode_srgb8(0.0f), 0);
    EXPECT_EQ(encode_srgb8(1.0f), 255);
    EXPECT_EQ(encode_srgb8(0.5f), 188);   // 1.055 * 0.5^(1/2.4) - 0.055 = 0.7354 -> 187.5 -> 188
    EXPECT_EQ(encode_srgb8(0.18f), 118);  // middle grey
    EXPECT_EQ(encode_srgb8(0.0031308f), 10);  // 12.92 * 0.0031308 * 255 = 10.3
    EXPECT_EQ(encode_srgb8(-3.0f), 0);
    EXPECT_EQ(encode_srgb8(7.0f), 255);
    EXPECT_EQ(encode_srgb8(std::numeric_limits<float>::quiet_NaN()), 0);
    EXPECT_EQ(encode_srgb8(std::numeric_limits<float>::infinity()), 255);
}

TEST(Film, MatchesTheDirectFormulaEverywhere) {
    for (int i = 0; i <= 200000; ++i) {
        const float v = static_cast<float>(i) / 200000.0f;
        ASSERT_EQ(encode_srgb8(v), reference_code(v)) << v;
    }
}

TEST(Film, AppliesExposureInsideRectOnly) {
    RgbFloatImage in({4, 3}, 0.25f);
    Rgb8Image out({4, 3}, 7);
    to_srgb8(in, {1, 1, 3, 2}, 2.0f, out);
    for (int y = 0; y < 3; ++y) {
        for (int x = 0; x < 4; ++x) {
            const bool inside = x >= 1 && x < 3 && y == 1;
            EXPECT_EQ(out.at(x, y)[2], inside ? 188 : 7) << x << "," << y;
        }
    }
    Rgb8Image small({2, 2});
    EXPECT_THROW(to_srgb8(in, {0, 0, 1, 1}, 1.0f, small), std::invalid_argument);
    EXPECT_THROW(to_srgb8(in, {0, 0, 5, 1}, 1.0f, out), std::invalid_argument);
    EXPECT_THROW(to_srgb8(in, {0, 0, 1, 1}, -1.0f, out), std::invalid_argument);
}

}  // namespace
}  // namespace mogao
