// SPDX-License-Identifier: Apache-2.0
// Numerical stability of the navigation filters at extreme time steps and inputs:
// steps of 0 (repeated timestamps), 1 us (a burst of samples) and 1 s (a stalled tracker), and
// non-finite samples. Each guard: outputs stay finite and inside the range of the inputs seen
// (a first-order low-pass is a convex blend, alpha in (0, 1]), and the Navigator's speeds never
// exceed the rate-mapping maxima.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "appliance/navigation/low_pass_filter.h"
#include "appliance/navigation/navigator.h"
#include "appliance/navigation/one_euro_filter.h"
#include "appliance/navigation/test_poses.h"

namespace mogao {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A signal with jumps of up to 1000 units between consecutive samples.
double jumpy(int i) { return (i % 3 == 0 ? 1000.0 : -250.0) * std::sin(0.7 * i); }

TEST(FilterTimeStep, SmoothingFactorStaysInUnitIntervalAtExtremeSteps) {
    for (const double fc : {1e-3, 1.0, 1e3, 1e9}) {
        for (const double dt : {1e-9, 1e-6, 1.0, 1e3}) {
            const double a = smoothing_factor(fc, dt);
            EXPECT_TRUE(std::isfinite(a)) << "fc " << fc << " dt " << dt;
            EXPECT_GT(a, 0.0) << "fc " << fc << " dt " << dt;
            EXPECT_LE(a, 1.0) << "fc " << fc << " dt " << dt;
        }
    }
    // An infinite cutoff (beta * |speed| overflowing) is a pass-through, not a NaN.
    EXPECT_EQ(smoothing_factor(kInf, 1e-6), 1.0);
}

// Feeds `jumpy` at a fixed step to both filters (beta large, so the One Euro cutoff sees speeds of
// 1e9 units/s at 1 us) and checks every output is finite and within the inputs' range.
void expect_bounded_at_step(double dt) {
    OneEuroFilter one_euro({0.5, 15.0, 1.0});
    LowPassFilter low_pass(0.5);
    double lo = kInf;
    double hi = -kInf;
    for (int i = 0; i < 2000; ++i) {
        const double x = jumpy(i);
        lo = std::min(lo, x);
        hi = std::max(hi, x);
        const double t = 100.0 + i * dt;
        for (const double y : {one_euro.filter(x, t), low_pass.filter(x, t)}) {
            ASSERT_TRUE(std::isfinite(y)) << "dt " << dt << " sample " << i;
            ASSERT_GE(y, lo) << "dt " << dt << " sample " << i;
            ASSERT_LE(y, hi) << "dt " << dt << " sample " << i;
        }
    }
}

TEST(FilterTimeStep, OneMicrosecondAndOneSecondStepsGiveBoundedOutputs) {
    expect_bounded_at_step(1e-6);
    expect_bounded_at_step(1.0);
}

TEST(FilterTimeStep, ZeroStepsChangeNothing) {
    OneEuroFilter one_euro({0.5, 15.0, 1.0});
    LowPassFilter low_pass(0.5);
    (void)one_euro.filter(1.0, 5.0);
    (void)low_pass.filter(1.0, 5.0);
    const double y1 = one_euro.filter(2.0, 5.000001);
    const double y2 = low_pass.filter(2.0, 5.000001);
    for (int i = 0; i < 100; ++i) {
        EXPECT_EQ(one_euro.filter(1e6 * i, 5.000001), y1);  // dt = 0: no division by zero
        EXPECT_EQ(low_pass.filter(1e6 * i, 5.000001), y2);
    }
}

// A NaN or infinite sample or timestamp must not poison the state: before the guard, an infinite
// sample made x^ infinite and the next finite sample gave inf - inf = NaN forever after; an
// infinite timestamp froze the filter (every later dt negative).
TEST(FilterTimeStep, NonFiniteSamplesAndTimesAreIgnored) {
    for (const double bad : {kNaN, kInf, -kInf}) {
        OneEuroFilter one_euro({0.5, 15.0, 1.0});
        LowPassFilter low_pass(0.5);
        (void)one_euro.filter(bad, 0.0);
        (void)low_pass.filter(bad, 0.0);
        (void)one_euro.filter(1.0, 0.1);
        (void)low_pass.filter(1.0, 0.1);
        (void)one_euro.filter(bad, 0.2);
        (void)low_pass.filter(bad, 0.2);
        (void)one_euro.filter(2.0, bad);
        (void)low_pass.filter(2.0, bad);
        double y_euro = 0.0;
        double y_low = 0.0;
        for (int i = 3; i < 300; ++i) {
            y_euro = one_euro.filter(3.0, 0.1 * i);
            y_low = low_pass.filter(3.0, 0.1 * i);
            ASSERT_TRUE(std::isfinite(y_euro) && std::isfinite(y_low)) << "bad value " << bad << " sample " << i;
            ASSERT_GE(std::min(y_euro, y_low), 1.0);
            ASSERT_LE(std::max(y_euro, y_low), 3.0);
        }
        // Still following the signal (not frozen): 30 s at 0.5 Hz converges to 3.
        EXPECT_NEAR(y_euro, 3.0, 1e-6) << "bad value " << bad;
        EXPECT_NEAR(y_low, 3.0, 1e-6) << "bad value " << bad;
    }
}

// The whole Navigator with camera samples and display frames 1 us apart (a burst), then 1 s apart
// (a stall): speeds stay within the mapped maxima and the pose stays finite.
void run_navigator(std::int64_t step_ns, int steps, Navigator& nav, const NavigationParams& p) {
    std::int64_t t = 0;
    for (int i = 0; i < steps; ++i, t += step_ns) {
        nav.observe(test::tag_sample(t, i % 2 == 0 ? 40.0 : -40.0, i % 3 == 0 ? 0.2 : 0.8));
        const ViewerPose pose = nav.advance(t);
        ASSERT_TRUE(pose.eye.allFinite() && std::isfinite(pose.yaw_deg) && std::isfinite(pose.pitch_deg))
            << "step " << step_ns << " ns, frame " << i;
        ASSERT_LE(std::abs(nav.velocity().turn_deg_s), p.turn.max_rate + 1e-9);
        ASSERT_LE(std::abs(nav.velocity().forward_m_s), p.forward.max_rate + 1e-9);
        ASSERT_LE(std::abs(pose.pitch_deg), p.pitch.max_deg + 1e-9);
    }
}

TEST(FilterTimeStep, NavigatorStaysBoundedAtMicrosecondAndSecondSteps) {
    NavigationParams p;
    p.pitch.enabled = true;
    for (const std::int64_t step : {std::int64_t{1'000}, std::int64_t{1'000'000'000}}) {
        Navigator nav(p, ViewerPose{});
        run_navigator(step, 400, nav, p);
    }
}

}  // namespace
}  // namespace mogao
