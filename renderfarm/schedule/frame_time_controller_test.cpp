// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/schedule/frame_time_controller.h"

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

namespace mogao {
namespace {

ViewRequest request_960x540(double scale = 1.0, int spp = 1) {
    ViewRequest r;
    r.size = {960, 540};
    r.quality.resolution_scale = scale;
    r.quality.spp = spp;
    return r;
}

// A synthetic farm: a frame costs a fixed overhead plus a time proportional to its work.
double synthetic_seconds(const FrameChoice& c, double seconds_per_full_frame, double overhead = 0.002) {
    return overhead + seconds_per_full_frame * c.work();
}

TEST(FrameTimeController, FirstFrameIsTheRequestAsAsked) {
    const FrameTimeController c({});
    const FrameChoice first = c.choose(request_960x540(0.5, 4));
    EXPECT_DOUBLE_EQ(first.resolution_scale, 0.5);
    EXPECT_EQ(first.spp, 4);
}

TEST(FrameTimeController, ConvergesToTheTargetOnASyntheticCostModel) {
    FrameTimeTarget t;
    t.target_seconds = 0.05;
    FrameTimeController c(t);
    const ViewRequest r = request_960x540();
    for (int i = 0; i < 40; ++i) {
        const FrameChoice used = c.choose(r);
        c.observe(used, synthetic_seconds(used, 0.2));  // full frame 4x too slow
    }
    const FrameChoice settled = c.choose(r);
    // Work that meets 50 ms: (0.05 - 0.002) / 0.2 = 0.24 -> scale sqrt(0.24).
    EXPECT_NEAR(settled.resolution_scale, std::sqrt(0.24), 0.01);
    EXPECT_EQ(settled.spp, 1);
    EXPECT_NEAR(synthetic_seconds(settled, 0.2), t.target_seconds, 0.003);
}

TEST(FrameTimeController, FastFarmSpendsTimeOnSamplesAtFullScale) {
    FrameTimeTarget t;
    t.target_seconds = 0.1;
    FrameTimeController c(t);
    const ViewRequest r = request_960x540();
    for (int i = 0; i < 40; ++i) {
        const FrameChoice used = c.choose(r);
        c.observe(used, synthetic_seconds(used, 0.02, 0.0));  // 1 spp takes a fifth of the target
    }
    const FrameChoice settled = c.choose(r);
    EXPECT_DOUBLE_EQ(settled.resolution_scale, 1.0);
    EXPECT_GE(settled.spp, 4);
    EXPECT_LE(settled.spp, 6);
}

TEST(FrameTimeController, ZeroFrameTimeClimbsToTheCeilingWithoutOverflow) {
    FrameTimeTarget t;
    t.max_spp = 8;
    FrameTimeController c(t);
    const ViewRequest r = request_960x540(0.75);
    for (int i = 0; i < 1000; ++i) c.observe(c.choose(r), 0.0);
    const FrameChoice top = c.choose(r);
    EXPECT_DOUBLE_EQ(top.resolution_scale, 0.75);  // never above the request's own scale
    EXPECT_EQ(top.spp, 8);
    EXPECT_TRUE(std::isfinite(c.work()));
}

TEST(FrameTimeController, HugeFrameTimeFallsToTheFloorAndRecovers) {
    FrameTimeTarget t;
    t.min_scale = 0.2;
    FrameTimeController c(t);
    const ViewRequest r = request_960x540();
    for (int i = 0; i < 1000; ++i) c.observe(c.choose(r), 1e9);
    EXPECT_DOUBLE_EQ(c.choose(r).resolution_scale, 0.2);
    EXPECT_EQ(c.choose(r).spp, 1);
    // A few fast frames bring it back up: the floor does not wind w down without bound.
    for (int i = 0; i < 10; ++i) c.observe(c.choose(r), 1e-4);
    EXPECT_DOUBLE_EQ(c.choose(r).resolution_scale, 1.0);
}

TEST(FrameTimeController, ScaleKeepsLinkMinimumSide) {
    FrameTimeTarget t;
    t.min_scale = 0.01;
    FrameTimeController c(t);
    ViewRequest r = request_960x540();
    r.size = {400, 100};
    for (int i = 0; i < 100; ++i) c.observe(c.choose(r), 1e9);
    r.quality.resolution_scale = c.choose(r).resolution_scale;
    EXPECT_EQ(render_size(r).height, 16);
}

TEST(FrameTimeController, RejectsBadTargets) {
    EXPECT_THROW(FrameTimeController({.target_seconds = 0.0}), std::invalid_argument);
    EXPECT_THROW(FrameTimeController({.gain = 1.5}), std::invalid_argument);
    EXPECT_THROW(FrameTimeController({.min_scale = 0.0}), std::invalid_argument);
    EXPECT_THROW(FrameTimeController({.max_spp = 0}), std::invalid_argument);
}

}  // namespace
}  // namespace mogao
