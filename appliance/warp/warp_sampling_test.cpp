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
    const WarpMap w = grid({4, 3}, [](int x, int y) { return 0.1F * x + 0.01F * y; },
                           [](int x, int y) { return 0.2F * y - 0.03F * x; });
    for (int y = 0; y < 3; ++y) {
        for (int x = 0; x < 4; ++x) {
            const ContentUv uv = sample_warp(w, {4, 3}, x, y);
            EXPECT_EQ(uv.u, w.uv[(y * 4 + x) * 2]);
            EXPECT_EQ(uv.v, w.uv[(y * 4 + x) * 2 + 1]);
        }
    }
}

TEST(WarpSampling, CoarseGridIsCornerAlignedOnPixelCentres) {
    // 2x2 samples over a 5x3 output: sample (1, 1) is pixel (4, 2), the middle pixel is the mean.
    const WarpMap w = grid({2, 2}, [](int x, int) { return x == 0 ? 0.0F : 1.0F; },
                           [](int, int y) { return y == 0 ? 0.25F : 0.75F; });
    const ImageSize out{5, 3};
    EXPECT_EQ(sample_warp(w, out, 0, 0).u, 0.0F);
    EXPECT_EQ(sample_warp(w, out, 4, 2).u, 1.0F);
    EXPECT_EQ(sample_warp(w, out, 4, 2).v, 0.75F);
    EXPECT_FLOAT_EQ(sample_warp(w, out, 1, 1).u, 0.25F);
    EXPECT_FLOAT_EQ(sample_warp(w, out, 2, 1).v, 0.5F);
    EXPECT_DOUBLE_EQ(output_to_grid(4.0, 5, 2), 1.0);
    EXPECT_DOUBLE_EQ(grid_to_output(1.0, 5, 2), 4.0);
    EXPECT_DOUBLE_EQ(output_to_grid(191.0 * 1919.0 / 191.0, 1920, 192), 191.0);
    EXPECT_DOUBLE_EQ(output_to_grid(3.0, 1, 1), 0.0);
}

TEST(WarpSampling, NanSamplesMeanNoContentButDoNotLeakAcrossZeroWeights) {
    WarpMap w = grid({3, 1}, [](int x, int) { return 0.5F * x; }, [](int, int) { return 0.5F; });
    w.uv[4] = NAN;  // sample 2 = no content
    w.uv[5] = NAN;
    const ImageSize out{5, 1};
    EXPECT_TRUE(sample_warp(w, out, 0, 0).valid());
    EXPECT_TRUE(sample_warp(w, out, 2, 0).valid());  // exactly on sample 1: sample 2 has weight 0
    EXPECT_FALSE(sample_warp(w, out, 3, 0).valid());
    EXPECT_FALSE(sample_warp(w, out, 4, 0).valid());
    EXPECT_TRUE(std::isnan(sample_warp(w, out, 3, 0).v));
}

TEST(WarpSampling, ContinuousPositionsInterpolateAndClamp) {
    const WarpMap w = grid({2, 2}, [](int x, int) { return static_cast<float>(x); },
                           [](int, int y) { return static_cast<float>(y); });
    const ImageSize out{11, 11};
    EXPECT_FLOAT_EQ(sample_warp_at(w, out, 2.5, 7.5).u, 0.25F);
    EXPECT_FLOAT_EQ(sample_warp_at(w, out, 2.5, 7.5).v, 0.75F);
    EXPECT_EQ(sample_warp_at(w, out, -3.0, 20.0).u, 0.0F);
    EXPECT_EQ(sample_warp_at(w, out, -3.0, 20.0).v, 1.0F);
}

TEST(WarpSampling, BlendIsBilinearOnTheSameConvention) {
    BlendMask b;
    b.size = {2, 1};
    b.weight = {0.0F, 1.0F};
    const ImageSize out{9, 4};
    EXPECT_EQ(sample_blend(b, out, 0, 3), 0.0F);
    EXPECT_EQ(sample_blend(b, out, 8, 0), 1.0F);
    EXPECT_FLOAT_EQ(sample_blend(b, out, 2, 1), 0.25F);
}

}  // namespace
}  // namespace mogao
