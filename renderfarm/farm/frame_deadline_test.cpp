// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/frame_deadline.h"

#include <gtest/gtest.h>

namespace mogao {
namespace {

ViewRequest view_of(int w, int h, int spp, int bounces) {
    ViewRequest v;
    v.size = {w, h};
    v.quality.spp = spp;
    v.quality.max_bounces = bounces;
    return v;
}

TEST(FrameDeadline, CostCountsRenderPixelsSamplesAndBounces) {
    EXPECT_DOUBLE_EQ(frame_cost_units(view_of(100, 50, 1, 0)), 5000.0);
    EXPECT_DOUBLE_EQ(frame_cost_units(view_of(100, 50, 4, 2)), 5000.0 * 4 * 3);
    ViewRequest half = view_of(100, 50, 1, 0);
    half.quality.resolution_scale = 0.5;
    EXPECT_DOUBLE_EQ(frame_cost_units(half), double(render_size(half).width) * render_size(half).height);
}

TEST(FrameDeadline, IsTheMaximumUntilAFrameWasMeasured) {
    FrameDeadline d({.max_s = 30, .min_s = 2, .factor = 4});
    EXPECT_DOUBLE_EQ(d.seconds_for(1e6), 30.0);
}

TEST(FrameDeadline, FollowsTheMeasuredRateWithinItsBounds) {
    FrameDeadline d({.max_s = 30, .min_s = 2, .factor = 4});
    d.observe(1e6, 1.0);                         // 1 us per unit
    EXPECT_DOUBLE_EQ(d.seconds_for(1e6), 4.0);   // 4 x 1 s
    EXPECT_DOUBLE_EQ(d.seconds_for(1e5), 2.0);   // 0.4 s, raised to the floor
    EXPECT_DOUBLE_EQ(d.seconds_for(1e8), 30.0);  // 400 s, cut to the maximum
}

TEST(FrameDeadline, UsesTheSlowestRecentFrameAndForgetsOldOnes) {
    FrameDeadline d({.max_s = 100, .min_s = 0, .factor = 1, .window = 3});
    d.observe(1e6, 5.0);  // a slow frame
    d.observe(1e6, 1.0);
    d.observe(1e6, 1.0);
    EXPECT_DOUBLE_EQ(d.seconds_for(1e6), 5.0);
    d.observe(1e6, 1.0);  // the slow one leaves the window
    EXPECT_DOUBLE_EQ(d.seconds_for(1e6), 1.0);
}

TEST(FrameDeadline, NoDeadlineAndFixedDeadlineModes) {
    FrameDeadline none({.max_s = 0});
    none.observe(1e6, 1.0);
    EXPECT_DOUBLE_EQ(none.seconds_for(1e6), 0.0);
    FrameDeadline fixed({.max_s = 30, .min_s = 2, .factor = 0});
    fixed.observe(1e6, 1.0);
    EXPECT_DOUBLE_EQ(fixed.seconds_for(1e6), 30.0);
}

TEST(FrameDeadline, IgnoresMeaninglessMeasurements) {
    FrameDeadline d({.max_s = 30, .min_s = 2, .factor = 4});
    d.observe(0, 1.0);
    d.observe(1e6, -1.0);
    EXPECT_DOUBLE_EQ(d.seconds_for(1e6), 30.0);
}

}  // namespace
}  // namespace mogao
