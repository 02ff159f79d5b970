// SPDX-License-Identifier: Apache-2.0
#include "appliance/warp/warp_sampling.h"

#include <cmath>

#include <gtest/gtest.h>

namespace mogao {
namespace {

WarpMap grid(ImageSize size, float (*u)(int, int), float (*v)(int, int)) {
    WarpMap w;
    w.size = size;
    for (int y = 0; y < size.height; ++y) {
        for (int x = 0; x < size.width; ++x) {
            w.uv.push_back(u(x, y));
            w.uv.push_back(v(x, y));
        }
    }
    return w;
}

TEST(WarpSampling, PerPixelGridIsUsedAsIs) {
    const WarpMap w = grid(
        {4, 3}, [](int x, int y) { return 0.1F * static_cast<float>(x) + 0.01F * static_cast<float>(y); },
        [](int x, int y) { return 0.2F * static_cast<float>(y) - 0.03F * static_cast<float>(x); });
    for (int y = 0; y < 3; ++y) {
        for (int x = 0; x < 4; ++x) {
            const ContentUv uv = sample_warp(w, {4, 3}, x, y);
            EXPECT_EQ(uv.u, w.uv[(y * 4 + x) * 2]);
            EXPECT_EQ(uv.v, w.uv[(y * 4 + x) * 2 + 1]);
        }
    }
}

TEST(WarpSampling, CoarseGridIsSampledAtTexelCentres) {
    // 2x2 samples over a 4x6 output: sample 0 sits at pixel centre 0.5 (x = 0.5 in pixel-index
    // coordinates), sample 1 at x = 2.5; pixels 0 and 3 clamp to the edge samples.
    const WarpMap w = grid(
        {2, 2}, [](int x, int) { return x == 0 ? 0.0F : 1.0F; }, [](int, int y) { return y == 0 ? 0.25F : 0.75F; });
    const ImageSize out{4, 6};
    EXPECT_EQ(sample_warp(w, out, 0, 0).u, 0.0F);
    EXPECT_EQ(sample_warp(w, out, 3, 5).u, 1.0F);
    EXPECT_EQ(sample_warp(w, out, 3, 5).v, 0.75F);
    EXPECT_FLOAT_EQ(sample_warp(w, out, 1, 0).u, 0.25F);  // g = 1.5 * 2 / 4 - 0.5 = 0.25
    EXPECT_FLOAT_EQ(sample_warp(w, out, 2, 0).u, 0.75F);
    EXPECT_FLOAT_EQ(sample_warp(w, out, 0, 2).v, 0.25F + 0.5F * (2.5F * 2.0F / 6.0F - 0.5F));
    EXPECT_DOUBLE_EQ(output_to_grid(2.5, 4, 2), 1.0);
    EXPECT_DOUBLE_EQ(grid_to_output(1.0, 4, 2), 2.5);
    EXPECT_DOUBLE_EQ(output_to_grid(1914.5, 1920, 192), 191.0);  // the last sample of a tenth-size grid
    EXPECT_DOUBLE_EQ(output_to_grid(7.0, 8, 8), 7.0);            // per-pixel: identity
}

TEST(WarpSampling, NanSamplesMeanNoContentButDoNotLeakAcrossZeroWeights) {
    WarpMap w = grid(
        {3, 1}, [](int x, int) { return 0.5F * static_cast<float>(x); }, [](int, int) { return 0.5F; });
    w.uv[4] = NAN;  // sample 2 = no content
    w.uv[5] = NAN;
    const ImageSize out{9, 1};  // sample k at pixel 3k + 1
    EXPECT_TRUE(sample_warp(w, out, 0, 0).valid());
    EXPECT_TRUE(sample_warp(w, out, 4, 0).valid());  // exactly on sample 1: sample 2 has weight 0
    EXPECT_FALSE(sample_warp(w, out, 5, 0).valid());
    EXPECT_FALSE(sample_warp(w, out, 8, 0).valid());
    EXPECT_TRUE(std::isnan(sample_warp(w, out, 5, 0).v));
}

TEST(WarpSampling, ContinuousPositionsInterpolateAndClamp) {
    const WarpMap w = grid(
        {2, 2}, [](int x, int) { return static_cast<float>(x); }, [](int, int y) { return static_cast<float>(y); });
    const ImageSize out{12, 12};  // samples at x = 2.5 and 8.5
    EXPECT_FLOAT_EQ(sample_warp_at(w, out, 4.0, 7.0).u, 0.25F);
    EXPECT_FLOAT_EQ(sample_warp_at(w, out, 4.0, 7.0).v, 0.75F);
    EXPECT_EQ(sample_warp_at(w, out, -3.0, 20.0).u, 0.0F);
    EXPECT_EQ(sample_warp_at(w, out, -3.0, 20.0).v, 1.0F);
}

TEST(WarpSampling, BlendIsBilinearOnTheSameConvention) {
    BlendMask b;
    b.size = {2, 1};
    b.weight = {0.0F, 1.0F};
    const ImageSize out{8, 4};  // samples at x = 1.5 and 5.5
    EXPECT_EQ(sample_blend(b, out, 0, 3), 0.0F);
    EXPECT_EQ(sample_blend(b, out, 7, 0), 1.0F);
    EXPECT_FLOAT_EQ(sample_blend(b, out, 2, 1), 0.125F);
}

}  // namespace
}  // namespace mogao
