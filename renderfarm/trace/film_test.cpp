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
    EXPECT_EQ(encode_srgb8(0.5f), 188);       // 1.055 * 0.5^(1/2.4) - 0.055 = 0.7354 -> 187.5 -> 188
    EXPECT_EQ(encode_srgb8(0.18f), 118);      // middle grey
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

// Row bands on threads write the same bytes as one thread, inside rect only, whatever the band count.
TEST(Film, ThreadedBandsWriteTheSameBytes) {
    RgbFloatImage in({37, 71});
    for (int y = 0; y < in.size.height; ++y)
        for (int x = 0; x < in.size.width; ++x)
            for (int c = 0; c < 3; ++c) in.at(x, y)[c] = 0.013f * static_cast<float>((x * 7 + y * 13 + c * 5) % 97);
    const PixelRect rect{3, 2, 35, 70};
    Rgb8Image one(in.size, 9);
    to_srgb8(in, rect, 1.5f, one, ToneMap::aces, 1);
    for (const int threads : {0, 2, 3, 8}) {
        Rgb8Image banded(in.size, 9);
        to_srgb8(in, rect, 1.5f, banded, ToneMap::aces, threads);
        EXPECT_EQ(banded.pixels, one.pixels) << threads << " threads";
    }
    EXPECT_EQ(one.at(0, 0)[0], 9);  // outside rect: untouched
    EXPECT_EQ(one.at(3, 2)[0], encode_srgb8(tone_map(ToneMap::aces, 1.5f * in.at(3, 2)[0])));
    EXPECT_THROW(to_srgb8(in, rect, 1.0f, one, ToneMap::clamp, -1), std::invalid_argument);
}

// Highlights: with clamp everything above 1 is one flat code; the tone maps keep an ordering
// up to several times white, match their formulas, and stay monotonic and within [0, 1].
TEST(Film, ToneMapsKeepHighlightsApart) {
    RgbFloatImage in({4, 1});
    const float values[4] = {0.18f, 1.0f, 2.0f, 4.0f};
    for (int x = 0; x < 4; ++x)
        for (int c = 0; c < 3; ++c) in.at(x, 0)[c] = values[x];
    Rgb8Image clamped(in.size);
    to_srgb8(in, PixelRect::whole(in.size), 1.0f, clamped, ToneMap::clamp);
    EXPECT_EQ(clamped.at(1, 0)[0], 255);
    EXPECT_EQ(clamped.at(3, 0)[0], 255);  // 1, 2 and 4 all clip to the same code
    for (const ToneMap op : {ToneMap::reinhard, ToneMap::aces}) {
        Rgb8Image out(in.size);
        to_srgb8(in, PixelRect::whole(in.size), 1.0f, out, op);
        for (int x = 1; x < 4; ++x) EXPECT_LT(out.at(x - 1, 0)[0], out.at(x, 0)[0]) << tone_map_name(op) << " " << x;
        EXPECT_LT(out.at(2, 0)[0], 255) << tone_map_name(op);
        float previous = 0.0f;
        for (int i = 0; i <= 1000; ++i) {
            const float x = 0.01f * static_cast<float>(i);
            const float v = tone_map(op, x);
            ASSERT_GE(v, previous) << tone_map_name(op) << " at " << x;
            ASSERT_GE(v, 0.0f);
            ASSERT_LE(v, 1.04f);  // the ACES fit tends to 2.51/2.43 before encode_srgb8 clamps
            previous = v;
        }
    }
    EXPECT_FLOAT_EQ(tone_map(ToneMap::reinhard, 3.0f), 0.75f);
    EXPECT_NEAR(tone_map(ToneMap::aces, 1.0f), (2.51 + 0.03) / (2.43 + 0.59 + 0.14), 1e-6);
    EXPECT_EQ(parse_tone_map("aces"), ToneMap::aces);
    EXPECT_THROW((void)parse_tone_map("filmic"), std::invalid_argument);
    Rgb8Image odd(in.size);
    in.at(0, 0)[0] = std::numeric_limits<float>::quiet_NaN();
    in.at(0, 0)[1] = std::numeric_limits<float>::infinity();
    to_srgb8(in, PixelRect::whole(in.size), 1.0f, odd, ToneMap::aces);
    EXPECT_EQ(odd.at(0, 0)[0], 0);
    EXPECT_EQ(odd.at(0, 0)[1], 255);
}

}  // namespace
}  // namespace mogao
