// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/progressive_accumulator.h"

#include <cmath>
#include <cstdint>
#include <stdexcept>

#include <gtest/gtest.h>

namespace mogao {
namespace {

ViewRequest small_view() {
    ViewRequest v;
    v.size = {4, 2};
    v.quality.spp = 1;
    return v;
}

RgbFloatImage filled(float value) { return RgbFloatImage({4, 2}, value); }

TEST(ProgressiveAccumulator, MeanIsTheSppWeightedAverageOfPasses) {
    ProgressiveAccumulator acc;
    ViewRequest v = small_view();
    EXPECT_EQ(acc.add(v, filled(1.f)), 1);
    v.quality.spp = 3;
    v.frame_id = 2;
    EXPECT_EQ(acc.add(v, filled(5.f)), 4);
    EXPECT_EQ(acc.passes(), 2);
    for (float p : acc.mean().pixels) EXPECT_FLOAT_EQ(p, (1.f + 3 * 5.f) / 4);
}

// Passes of 2 spp drawn from a known distribution (per-sample σ = 0.5): the pass-to-pass estimate
// of the mean's variance approaches σ² / N, and one pass gives none.
TEST(ProgressiveAccumulator, VarianceOfTheMeanIsEstimatedFromThePassesSpread) {
    ProgressiveAccumulator acc;
    ViewRequest v = small_view();
    v.quality.spp = 2;
    EXPECT_TRUE(acc.variance_of_mean().pixels.empty());
    const double sigma = 0.5;
    const int passes = 400;
    std::uint64_t state = 12345;
    const auto uniform = [&] {  // splitmix64 -> [0, 1)
        std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
        return static_cast<double>((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
    };
    for (int k = 0; k < passes; ++k) {
        RgbFloatImage pass({4, 2});
        for (float& p : pass.pixels) {  // mean of 2 samples, each 1 ± sigma·sqrt(3)·(2u - 1): variance sigma²
            const double a = 1.0 + sigma * std::sqrt(3.0) * (2 * uniform() - 1);
            const double b = 1.0 + sigma * std::sqrt(3.0) * (2 * uniform() - 1);
            p = static_cast<float>((a + b) / 2);
        }
        v.frame_id = pass_frame_id(1, k);
        acc.add(v, pass);
        if (k == 0) {
            EXPECT_TRUE(acc.variance_of_mean().pixels.empty()) << "one pass has no spread";
        }
    }
    const RgbFloatImage var = acc.variance_of_mean();
    ASSERT_EQ(var.size, (ImageSize{4, 2}));
    double mean_var = 0;
    for (float p : var.pixels) mean_var += p / static_cast<double>(var.pixels.size());
    const double expected = sigma * sigma / (2.0 * passes);
    EXPECT_NEAR(mean_var, expected, 0.15 * expected);
    v.pose.eye.x() += 1;  // a new view starts over: no variance until its second pass
    acc.add(v, filled(1.f));
    EXPECT_TRUE(acc.variance_of_mean().pixels.empty());
}

TEST(ProgressiveAccumulator, AnyChangeOfViewStartsOver) {
    const auto changed = [](auto&& change) {
        ProgressiveAccumulator acc;
        ViewRequest v = small_view();
        acc.add(v, filled(1.f));
        change(v);
        acc.add(v, filled(3.f));
        return acc.passes() == 1 && acc.mean().pixels[0] == 3.f;
    };
    EXPECT_TRUE(changed([](ViewRequest& v) { v.pose.eye.x() += 1e-9; }));
    EXPECT_TRUE(changed([](ViewRequest& v) { v.pose.yaw_deg += 0.01; }));
    EXPECT_TRUE(changed([](ViewRequest& v) { v.pose.pitch_deg += 0.01; }));
    EXPECT_TRUE(changed([](ViewRequest& v) { v.camera = PinholeCamera{61.0}; }));
    EXPECT_TRUE(changed([](ViewRequest& v) { v.camera = CylinderScreen{}; }));
    EXPECT_TRUE(changed([](ViewRequest& v) { v.quality.max_bounces = 1; }));
    EXPECT_TRUE(changed([](ViewRequest& v) { v.quality.ao_samples = 2; }));
    EXPECT_TRUE(changed([](ViewRequest& v) { v.quality.area_light_samples = 2; }));
    EXPECT_TRUE(changed([](ViewRequest& v) { v.seed = 2; }));
    // Only sampling bookkeeping and encoding change: the accumulation goes on.
    EXPECT_FALSE(changed([](ViewRequest& v) {
        v.frame_id = 9;
        v.request_time_ns = 5;
        v.quality.jpeg_quality = 50;
        v.quality.spp = 1;
    }));
}

TEST(ProgressiveAccumulator, CylinderScreensCompareEveryField) {
    ViewRequest a = small_view();
    a.camera = CylinderScreen{};
    ViewRequest b = a;
    EXPECT_TRUE(same_view(a, b));
    std::get<CylinderScreen>(b.camera).eye_m.y() += 0.01;
    EXPECT_FALSE(same_view(a, b));
    b = a;
    std::get<CylinderScreen>(b.camera).arc_deg = 90;
    EXPECT_FALSE(same_view(a, b));
}

TEST(ProgressiveAccumulator, PassFrameIdsAreDistinctAndPassZeroIsTheRequest) {
    EXPECT_EQ(pass_frame_id(17, 0), 17u);
    EXPECT_NE(pass_frame_id(17, 1), pass_frame_id(18, 0));
    EXPECT_NE(pass_frame_id(17, 1), pass_frame_id(17, 2));
    EXPECT_NE(pass_frame_id(17, 1), pass_frame_id(18, 1));
    EXPECT_THROW((void)pass_frame_id(1, -1), std::invalid_argument);
}

TEST(ProgressiveAccumulator, RejectsPassOfTheWrongSize) {
    ProgressiveAccumulator acc;
    EXPECT_THROW(acc.add(small_view(), RgbFloatImage({3, 2})), std::invalid_argument);
    EXPECT_EQ(acc.samples(), 0);
    EXPECT_TRUE(acc.mean().pixels.empty());
}

}  // namespace
}  // namespace mogao
