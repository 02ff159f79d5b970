// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/progressive_accumulator.h"

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
