// SPDX-License-Identifier: Apache-2.0
#include "appliance/navigation/one_euro_filter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "appliance/navigation/low_pass_filter.h"

namespace mogao {
namespace {

TEST(OneEuroFilter, FirstSamplePassesAndConstantStaysConstant) {
    OneEuroFilter f({1.0, 0.5, 1.0});
    EXPECT_EQ(f.filter(3.0, 0.0), 3.0);
    for (int i = 1; i < 50; ++i) EXPECT_DOUBLE_EQ(f.filter(3.0, i / 30.0), 3.0);
}

TEST(OneEuroFilter, OneStepFollowsThePaperFormulas) {
    const OneEuroParams p{1.0, 0.5, 2.0};
    OneEuroFilter f(p);
    (void)f.filter(0.0, 0.0);
    const double dt = 0.1;
    const double tau_d = 1.0 / (2.0 * std::numbers::pi * p.d_cutoff_hz);
    const double dx_hat = (1.0 / (1.0 + tau_d / dt)) * (1.0 - 0.0) / dt;
    const double fc = p.min_cutoff_hz + p.beta * std::abs(dx_hat);
    const double alpha = 1.0 / (1.0 + 1.0 / (2.0 * std::numbers::pi * fc * dt));
    EXPECT_NEAR(f.filter(1.0, dt), alpha * 1.0, 1e-12);
}

TEST(OneEuroFilter, WithBetaZeroItIsTheLowPassAtMinCutoff) {
    OneEuroFilter one_euro({2.0, 0.0, 1.0});
    LowPassFilter low_pass(2.0);
    for (int i = 0; i < 100; ++i) {
        const double x = std::sin(i * 0.3) + (i % 7) * 0.1;
        EXPECT_NEAR(one_euro.filter(x, i / 30.0), low_pass.filter(x, i / 30.0), 1e-12);
    }
}

TEST(OneEuroFilter, BetaCutsTheLagOfAFastRamp) {
    OneEuroFilter slow({1.0, 0.0, 1.0});
    OneEuroFilter fast({1.0, 0.05, 1.0});
    double slow_error = 0.0;
    double fast_error = 0.0;
    for (int i = 0; i <= 30; ++i) {  // 100 deg/s for one second
        const double t = i / 30.0;
        slow_error = 100.0 * t - slow.filter(100.0 * t, t);
        fast_error = 100.0 * t - fast.filter(100.0 * t, t);
    }
    EXPECT_GT(slow_error, 3.0 * fast_error);
    EXPECT_GT(fast_error, 0.0);
}

TEST(OneEuroFilter, RepeatedTimestampChangesNothing) {
    OneEuroFilter f({1.0, 0.0, 1.0});
    (void)f.filter(0.0, 1.0);
    const double y = f.filter(10.0, 1.1);
    EXPECT_EQ(f.filter(1000.0, 1.1), y);
    EXPECT_EQ(f.filter(1000.0, 1.0), y);
}

TEST(OneEuroFilter, BadParametersNameTheField) {
    try {
        OneEuroFilter f({0.0, 0.0, 1.0});
        FAIL() << "expected invalid_argument";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("min_cutoff_hz"), std::string::npos) << e.what();
    }
    EXPECT_THROW(OneEuroFilter({1.0, -1.0, 1.0}), std::invalid_argument);
    EXPECT_THROW(OneEuroFilter({1.0, 0.0, std::nan("")}), std::invalid_argument);
    EXPECT_THROW(LowPassFilter(0.0), std::invalid_argument);
}

}  // namespace
}  // namespace mogao
