// SPDX-License-Identifier: Apache-2.0
// The pose-change Kalman filter: time steps of 0, 1 us and 1 s; a single bad frame does nothing;
// a real step is followed; bad input is refused.
#include "appliance/selfcal/pose_kalman.h"

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

namespace mogao::selfcal {
namespace {

Cov6 measurement_cov(double rot_sd, double pos_sd) {
    Cov6 r = Cov6::Zero();
    r.diagonal() << rot_sd * rot_sd, rot_sd * rot_sd, rot_sd * rot_sd, pos_sd * pos_sd, pos_sd * pos_sd,
        pos_sd * pos_sd;
    return r;
}

TEST(PoseKalman, TimeStepsZeroMicroAndOneSecondStayFiniteAndSensible) {
    for (const double dt : {0.0, 1e-6, 1.0}) {
        PoseKalman f;
        const Cov6 p0 = f.covariance();
        f.predict(dt);
        const Cov6 p1 = f.covariance();
        ASSERT_TRUE(p1.allFinite()) << dt;
        // P grows with dt, by exactly Q dt; at dt = 0 not at all.
        EXPECT_NEAR((p1 - p0).diagonal()(0), 2e-5 * 2e-5 * dt, 1e-18) << dt;
        EXPECT_GE((p1 - p0).diagonal().minCoeff(), 0.0) << dt;
        // An update right after moves the state toward the measurement and shrinks P.
        Pose6 z = Pose6::Zero();
        z(0) = 1e-4;
        EXPECT_EQ(f.update(z, measurement_cov(1e-4, 1e-3)), KalmanUpdate::accepted) << dt;
        EXPECT_TRUE(f.state().allFinite());
        EXPECT_GT(f.state()(0), 0.0);
        EXPECT_LT(f.state()(0), 1e-4);
        EXPECT_LT(f.covariance()(0, 0), p1(0, 0));
        // Many repeated zero-length steps change nothing.
        const Pose6 x = f.state();
        for (int i = 0; i < 1000; ++i) f.predict(dt == 1.0 ? 0.0 : dt);
        EXPECT_EQ(f.state(), x);
    }
}

TEST(PoseKalman, RefusesNegativeOrNonFiniteTimeSteps) {
    PoseKalman f;
    EXPECT_THROW(f.predict(-1e-6), std::invalid_argument);
    EXPECT_THROW(f.predict(std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
    EXPECT_THROW(f.predict(std::numeric_limits<double>::infinity()), std::invalid_argument);
    Pose6 z = Pose6::Zero();
    z(2) = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW((void)f.update(z, measurement_cov(1e-4, 1e-3)), std::invalid_argument);
}

TEST(PoseKalman, OneBadFrameDoesNothingAStepIsFollowed) {
    PoseKalman f;
    std::mt19937 rng(3);
    std::normal_distribution<double> n(0.0, 1.0);
    const Cov6 r = measurement_cov(5e-5, 5e-4);
    const auto noisy = [&](const Pose6& mean) {
        Pose6 z = mean;
        for (int i = 0; i < 6; ++i) z(i) += (i < 3 ? 5e-5 : 5e-4) * n(rng);
        return z;
    };
    for (int i = 0; i < 20; ++i) {
        f.predict(0.5);
        (void)f.update(noisy(Pose6::Zero()), r);
    }
    // A single wild frame (1 degree) is rejected and leaves the state where it was.
    Pose6 wild = Pose6::Zero();
    wild(1) = 0.0175;
    const Pose6 before = f.state();
    f.predict(0.5);
    EXPECT_EQ(f.update(wild, r), KalmanUpdate::rejected);
    EXPECT_EQ(f.state(), before);
    f.predict(0.5);
    (void)f.update(noisy(Pose6::Zero()), r);
    EXPECT_LT(f.state()(1), 1e-4);
    // A real step (the same 1 degree, frame after frame) is taken within step_frames frames.
    int frames = 0;
    while (std::abs(f.state()(1) - 0.0175) > 1e-4 && frames < 10) {
        f.predict(0.5);
        (void)f.update(noisy(wild), r);
        ++frames;
    }
    EXPECT_LE(frames, 3);
    EXPECT_NEAR(f.state()(1), 0.0175, 1e-4);
}

}  // namespace
}  // namespace mogao::selfcal
