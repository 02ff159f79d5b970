// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/schedule/frame_time_controller.h"

#include <cmath>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

namespace mogao {
namespace {

ViewRequest request_960x540(double scale = 1.0, int spp = 1, int bounces = 0) {
    ViewRequest r;
    r.size = {960, 540};
    r.quality.resolution_scale = scale;
    r.quality.spp = spp;
    r.quality.max_bounces = bounces;
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
    t.min_scale = 0.2;  // the settled scale, 0.49, lies below the default floor
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

// Frames served per second = frames / the sum of their times: the ARITHMETIC mean frame time must
// meet the target. A farm whose frame time jitters log-normally (sigma = 0.3, i.i.d.) around a cost
// proportional to the work: aiming at the target itself settles the geometric mean there and the
// arithmetic mean about 6 % above it (exp(Var(log t) / 2), Var(log t) = sigma^2 * 4 / 3 with the
// damped step's own share; frame_time_controller.h).
double mean_settled_seconds(FrameTimeTarget t) {
    FrameTimeController c(t);
    const ViewRequest r = request_960x540();
    std::mt19937_64 rng(11);
    std::normal_distribution<double> eta(0.0, 0.3);
    double sum = 0.0;
    int counted = 0;
    for (int i = 0; i < 40000; ++i) {
        const FrameChoice used = c.choose(r);
        const double seconds = 0.2 * used.work() * std::exp(eta(rng));
        c.observe(used, seconds);
        if (i >= 1000) {
            sum += seconds;
            ++counted;
        }
    }
    return sum / counted;
}

TEST(FrameTimeController, MeanFrameTimeMeetsTheTargetDespiteJitter) {
    FrameTimeTarget t;
    t.target_seconds = 0.05;
    t.min_scale = 0.2;  // the settled scale, about 0.5, would touch the default floor
    t.headroom = 0.0;
    const double mean = mean_settled_seconds(t);
    EXPECT_LE(mean, 1.01 * t.target_seconds) << "the served rate falls short of the target's";
    EXPECT_GE(mean, 0.97 * t.target_seconds) << "the allowance for jitter wastes the frame time";
    t.headroom = 0.02;  // the default: the mean 2 % inside the target
    EXPECT_NEAR(mean_settled_seconds(t), 0.98 * mean, 0.01 * t.target_seconds);
    // Without the allowance the arithmetic mean misses: what the test guards against.
    t.headroom = 0.0;
    t.jitter_weight = 0.0;
    EXPECT_GT(mean_settled_seconds(t), 1.04 * t.target_seconds);
}

TEST(FrameTimeController, AStallOrANewViewIsNotTakenForJitter) {
    FrameTimeTarget t;
    t.target_seconds = 0.05;
    t.min_scale = 0.2;
    FrameTimeController c(t);
    const ViewRequest r = request_960x540();
    for (int i = 0; i < 200; ++i) {
        const FrameChoice used = c.choose(r);
        c.observe(used, 0.2 * used.work());  // steady: no jitter once settled
    }
    EXPECT_NEAR(c.jitter_allowance(), 1.0, 1e-6);
    const double aim = c.aim_seconds();
    c.observe(c.choose(r), 30.0);  // a stall: the step is clamped, the means untouched
    EXPECT_DOUBLE_EQ(c.aim_seconds(), aim);
    // Wild frames within the step bound lower the aim, never below min_aim of the target.
    for (int i = 0; i < 200; ++i) {
        const FrameChoice used = c.choose(r);
        c.observe(used, (i % 2 == 0 ? 0.4 : 0.1) * used.work());
    }
    EXPECT_GE(c.aim_seconds(), t.min_aim * t.target_seconds);
    EXPECT_LT(c.aim_seconds(), t.target_seconds);
}

// A caller that needs 3 ms after each frame before it asks for the next (the encoder's hand-off):
// the period, frame plus hand-off, meets the target; a gap as long as a 10 Hz appliance's pause
// between requests is its pace, not the farm's cost, and shrinks nothing.
double settled_frame_seconds(FrameTimeTarget t, double gap) {
    FrameTimeController c(t);
    const ViewRequest r = request_960x540();
    double seconds = 0.0;
    for (int i = 0; i < 80; ++i) {
        const FrameChoice used = c.choose(r);
        seconds = 0.2 * used.work();
        c.observe(used, seconds, gap);
    }
    return seconds;
}

TEST(FrameTimeController, AHandOffBetweenBackToBackFramesIsChargedAndAnIdlePauseIsNot) {
    FrameTimeTarget t;
    t.target_seconds = 0.05;
    t.min_scale = 0.2;
    t.headroom = 0.0;
    EXPECT_NEAR(settled_frame_seconds(t, 0.003) + 0.003, t.target_seconds, 1e-4);
    EXPECT_NEAR(settled_frame_seconds(t, 0.05), t.target_seconds, 1e-4);
    EXPECT_NEAR(settled_frame_seconds(t, std::nan("")), t.target_seconds, 1e-4);
    FrameTimeController c(t);
    EXPECT_DOUBLE_EQ(c.charged_gap(0.003), 0.003);
    EXPECT_DOUBLE_EQ(c.charged_gap(0.0125), 0.0);  // max_handoff * target: a pause
    EXPECT_DOUBLE_EQ(c.charged_gap(-1.0), 0.0);
    t.max_handoff = 0.0;
    EXPECT_NEAR(settled_frame_seconds(t, 0.003), t.target_seconds, 1e-4);
}

TEST(FrameTimeController, RejectsBadTargets) {
    EXPECT_THROW(FrameTimeController({.target_seconds = 0.0}), std::invalid_argument);
    EXPECT_THROW(FrameTimeController({.gain = 1.5}), std::invalid_argument);
    EXPECT_THROW(FrameTimeController({.min_scale = 0.0}), std::invalid_argument);
    EXPECT_THROW(FrameTimeController({.max_spp = 0}), std::invalid_argument);
    EXPECT_THROW(FrameTimeController({.jitter_weight = 1.0}), std::invalid_argument);
    EXPECT_THROW(FrameTimeController({.min_aim = 0.0}), std::invalid_argument);
    EXPECT_THROW(FrameTimeController({.max_handoff = 1.0}), std::invalid_argument);
    EXPECT_THROW(FrameTimeController({.headroom = 0.5}), std::invalid_argument);  // below min_aim
    EXPECT_THROW(FrameTimeController({.min_bounces = -1}), std::invalid_argument);
    EXPECT_THROW(FrameTimeController({.bounce_cost = 0.0}), std::invalid_argument);
    EXPECT_THROW(FrameTimeController({.climb_margin = 0.0}), std::invalid_argument);
    // The default keeps the first bounce however slow the frames.
    FrameTimeController slow(FrameTimeTarget{});
    const ViewRequest r = request_960x540(1.0, 1, 3);
    for (int i = 0; i < 50; ++i) slow.observe(slow.choose(r), 1e3);
    EXPECT_EQ(slow.choose(r).bounces, 1);
}

// A synthetic farm whose bounces cost more than the controller's model says (3.5 times a
// direct-light-only frame per bounce against its 2.5): k seconds per full 1-spp direct-only frame.
double seconds_with_bounces(const FrameChoice& c, const ViewRequest& r, double k) {
    const int b = c.bounces < 0 ? r.quality.max_bounces : c.bounces;
    return k * c.resolution_scale * c.resolution_scale * c.spp * (1.0 + 3.5 * b);
}

// Samples go first, resolution last: spp is 1 whenever the scale is below the request's, and a
// bounce is dropped only at the floor.
void expect_samples_before_resolution(const FrameChoice& c, const ViewRequest& r, double floor) {
    if (c.resolution_scale < r.quality.resolution_scale) {
        EXPECT_EQ(c.spp, 1);
    }
    if (c.bounces < r.quality.max_bounces) {
        EXPECT_DOUBLE_EQ(c.resolution_scale, floor);
    }
    EXPECT_GE(c.resolution_scale, floor - 1e-12) << "below the floor of the resolution scale";
}

TEST(FrameTimeController, UnderHeavyOverloadTheScaleHoldsItsFloorAndSamplesAndBouncesGo) {
    FrameTimeTarget t;  // the default floor, 0.5
    t.target_seconds = 0.05;
    t.min_bounces = 0;
    FrameTimeController c(t);
    const ViewRequest r = request_960x540(1.0, 4, 2);
    FrameChoice used;
    for (int i = 0; i < 200; ++i) {
        used = c.choose(r);
        expect_samples_before_resolution(used, r, 0.5);
        c.observe(used, seconds_with_bounces(used, r, 0.4));  // even the floor at 0 bounces is 2x too slow
    }
    EXPECT_DOUBLE_EQ(used.resolution_scale, 0.5);
    EXPECT_EQ(used.spp, 1);
    EXPECT_EQ(used.bounces, 0);
}

TEST(FrameTimeController, BouncesFallOnlyAsFarAsNeededHoldStillAndComeBackFirst) {
    FrameTimeTarget t;
    t.target_seconds = 0.05;
    t.min_bounces = 0;
    FrameTimeController c(t);
    const ViewRequest r = request_960x540(1.0, 1, 2);
    // At the floor 2 bounces take 80 ms, 1 bounce 45 ms: one bounce goes, and stays gone.
    int changes = 0, last = -1;
    FrameChoice used;
    for (int i = 0; i < 300; ++i) {
        used = c.choose(r);
        expect_samples_before_resolution(used, r, 0.5);
        if (i >= 50 && used.bounces != last) ++changes;
        last = used.bounces;
        c.observe(used, seconds_with_bounces(used, r, 0.04));
    }
    EXPECT_EQ(used.bounces, 1);
    EXPECT_DOUBLE_EQ(used.resolution_scale, 0.5);
    EXPECT_EQ(changes, 0) << "the depth flickers between levels";
    // The load eases (a quarter of the cost): the bounce comes back before the scale rises.
    bool rose_before_bounce = false;
    for (int i = 0; i < 60; ++i) {
        used = c.choose(r);
        rose_before_bounce |= used.bounces < 2 && used.resolution_scale > 0.5;
        c.observe(used, seconds_with_bounces(used, r, 0.01));
    }
    EXPECT_FALSE(rose_before_bounce);
    EXPECT_EQ(used.bounces, 2);
    // Work meeting the 49 ms aim: 0.049 / (0.01 * 8) -> scale sqrt(0.6125).
    EXPECT_NEAR(used.resolution_scale, std::sqrt(0.6125), 0.02);
}

TEST(FrameTimeController, SetTargetSecondsChangesTheAimAndRefusesNonPositiveOrNaN) {
    FrameTimeTarget t;
    t.target_seconds = 0.1;
    t.jitter_weight = 0;
    t.headroom = 0;
    FrameTimeController c(t);
    c.set_target_seconds(0.025);
    EXPECT_DOUBLE_EQ(c.target().target_seconds, 0.025);
    EXPECT_DOUBLE_EQ(c.aim_seconds(), 0.025);
    EXPECT_THROW(c.set_target_seconds(0.0), std::invalid_argument);
    EXPECT_THROW(c.set_target_seconds(std::nan("")), std::invalid_argument);
    EXPECT_DOUBLE_EQ(c.target().target_seconds, 0.025);  // a refused target leaves the last good one
}

}  // namespace
}  // namespace mogao
