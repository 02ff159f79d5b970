// SPDX-License-Identifier: Apache-2.0
// The texture's mip chain and filtered lookups (texture.h): sizes down to 1x1, every texel counted
// (odd sides too), light preserved down the chain, level 0 untouched, trilinear in between.
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

#include "common/srgb.h"
#include "renderfarm/scene/texture.h"

namespace mogao {
namespace {

Rgb8Image random_image(ImageSize size, unsigned seed) {
    Rgb8Image image(size);
    std::mt19937 rng(seed);
    for (auto& c : image.pixels) c = static_cast<std::uint8_t>(rng() % 256);
    return image;
}

// Mean linear light of an image, per channel.
Eigen::Vector3d mean_linear(const Rgb8Image& image) {
    const auto& lut = srgb8_decode_table();
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < image.pixels.size(); ++i) sum[static_cast<Eigen::Index>(i % 3)] += lut[image.pixels[i]];
    return sum / static_cast<double>(image.size.pixel_count());
}

TEST(TextureMips, ChainHalvesEachSideDownToOneTexel) {
    const auto chain = make_mip_chain(Rgb8Image({256, 64}));
    ASSERT_EQ(chain.size(), 8u);  // 128x32 64x16 32x8 16x4 8x2 4x1 2x1 1x1
    EXPECT_EQ(chain[0].size, (ImageSize{128, 32}));
    EXPECT_EQ(chain[5].size, (ImageSize{4, 1}));
    EXPECT_EQ(chain[7].size, (ImageSize{1, 1}));
    EXPECT_EQ(make_mip_chain(Rgb8Image({5, 3})).size(), 2u);  // 2x1, 1x1
    EXPECT_TRUE(make_mip_chain(Rgb8Image({1, 1})).empty());
    EXPECT_THROW((void)make_mip_chain(Rgb8Image{}), std::invalid_argument);
}

TEST(TextureMips, EveryLevelKeepsTheMeanLightOfLevelZero) {
    const Rgb8Image image = random_image({128, 64}, 7);
    const Eigen::Vector3d mean = mean_linear(image);
    for (const Rgb8Image& level : make_mip_chain(image)) {
        // Each level is rounded once to sRGB8 (half a code: under 0.5 % of the mean here).
        EXPECT_LT((mean_linear(level) - mean).cwiseAbs().maxCoeff(), 2e-3)
            << level.size.width << "x" << level.size.height;
    }
}

TEST(TextureMips, AnOddSidesLastTexelIsCountedNotDropped) {
    // 3x3: the single level-1 texel averages all nine; a white last column must show.
    Rgb8Image image({3, 3}, 0);
    for (int y = 0; y < 3; ++y)
        for (int c = 0; c < 3; ++c) image.at(2, y)[c] = 255;
    const auto chain = make_mip_chain(image);
    ASSERT_EQ(chain.size(), 1u);
    const long expected = std::lround(255.0 * srgb_encode(3.0 / 9.0));
    EXPECT_EQ(static_cast<long>(chain[0].at(0, 0)[0]), expected);
}

TEST(TextureMips, FiltersLightNotCodes) {
    // A one-texel checker of codes 0 and 255 averages to linear 0.5 (code 188), not code 128.
    Rgb8Image image({64, 64});
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x)
            for (int c = 0; c < 3; ++c) image.at(x, y)[c] = (x + y) % 2 ? 255 : 0;
    const auto chain = make_mip_chain(image);
    for (const std::uint8_t code : chain[0].pixels) ASSERT_EQ(code, 188);
}

TEST(TextureSample, LevelOfDetailZeroOrBelowIsTheBilinearLevelZeroSample) {
    Texture t;
    t.image = random_image({32, 16}, 3);
    t.mips = make_mip_chain(t.image);
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> uv(-1.5f, 2.5f);
    for (int i = 0; i < 200; ++i) {
        const Eigen::Vector2f p(uv(rng), uv(rng));
        for (const float lod : {0.0f, -3.0f, std::nanf("")}) ASSERT_EQ(t.sample(p, lod), t.sample(p)) << lod;
    }
}

TEST(TextureSample, TrilinearBetweenLevelsAndClampedToTheLast) {
    Texture t;
    t.image = random_image({32, 32}, 5);
    t.mips = make_mip_chain(t.image);  // 5 levels above 0
    const Eigen::Vector2f p(0.37f, 0.61f);
    const Eigen::Vector3f l1 = texture_detail::bilinear(t.mips[0], p, t.wrap_u, t.wrap_v);
    const Eigen::Vector3f l2 = texture_detail::bilinear(t.mips[1], p, t.wrap_u, t.wrap_v);
    EXPECT_TRUE(t.sample(p, 1.0f).isApprox(l1));
    EXPECT_TRUE(t.sample(p, 1.25f).isApprox(0.75f * l1 + 0.25f * l2));
    const Eigen::Vector3f top = texture_detail::bilinear(t.mips.back(), p, t.wrap_u, t.wrap_v);
    EXPECT_TRUE(t.sample(p, 5.0f).isApprox(top));
    EXPECT_TRUE(t.sample(p, 40.0f).isApprox(top));
    EXPECT_TRUE(t.sample(p, std::numeric_limits<float>::infinity()).isApprox(top));
    // Without a chain, level 0 whatever the level of detail.
    t.mips.clear();
    EXPECT_EQ(t.sample(p, 3.0f), t.sample(p));
}

}  // namespace
}  // namespace mogao
