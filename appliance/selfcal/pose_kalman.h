// SPDX-License-Identifier: Apache-2.0
// A Kalman filter (Kalman 1960) over one rigid device's pose change, so that one bad frame does
// nothing and a real bump is followed within a few frames.
//
// State: the 6-vector pose change of a device against its calibrated pose, x = (w, d): w the
// rotation vector (radians, device frame: R_now = R_cal * exp([w]x)), d the position change
// (metres, screen frame: p_now = p_cal + d). Model: a random walk (a mount sags slowly), so
// predict() keeps x and adds Q * dt to P, Q = diag(q_rot^2 x3, q_pos^2 x3) per second.
// Measurements z = x + noise with the covariance R of the robust pose fit (robust_pose.h).
// Gating: an update whose Mahalanobis distance y^T (P + R)^-1 y exceeds `gate_chi2` (chi-square,
// 6 degrees of freedom; 22.46 = 99.9 %) is rejected as an outlier (Bar-Shalom, Li, Kirubarajan
// 2001, "Estimation with applications to tracking and navigation", 5.4 validation gate). A step
// change (a bump) is accepted when `step_frames` rejected measurements in a row agree with each
// other (each within the gate of their information-weighted mean): the state restarts from that
// mean with its covariance. The update uses Joseph's form, which keeps P symmetric positive.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace mogao::selfcal {

using Pose6 = Eigen::Matrix<double, 6, 1>;
using Cov6 = Eigen::Matrix<double, 6, 6>;

struct KalmanOptions {
    double rotation_walk_rad = 2e-5;        // q_rot: random-walk rate, rad per sqrt(second), >= 0
    double position_walk_m = 2e-5;          // q_pos: m per sqrt(second), >= 0
    double initial_rotation_sd_rad = 2e-4;  // trust in the calibration at the start, > 0
    double initial_position_sd_m = 1e-3;    // > 0
    double gate_chi2 = 22.46;               // > 0
    int step_frames = 3;                    // rejected, agreeing measurements that make a step, >= 1
};

enum class KalmanUpdate { accepted, rejected, step_accepted };

class PoseKalman {
public:
    // Throws std::invalid_argument naming the option and its limit.
    explicit PoseKalman(const KalmanOptions& options = {});

    // Advances time by dt_s seconds: P += Q dt. dt = 0 changes nothing. Throws
    // std::invalid_argument for a negative or non-finite dt.
    void predict(double dt_s);

    // One measurement of the pose change and its covariance (symmetric positive definite).
    // Throws std::invalid_argument for non-finite values or a singular P + R.
    KalmanUpdate update(const Pose6& z, const Cov6& r);

    // Starts again at x with covariance p (after a correction: the new calibration is the zero).
    void reset(const Pose6& x, const Cov6& p);
    void reset();  // zero with the initial covariance

    [[nodiscard]] const Pose6& state() const { return x_; }
    [[nodiscard]] const Cov6& covariance() const { return p_; }
    // x^T P^-1 x: how far the state is from "no change" in its own uncertainty.
    [[nodiscard]] double significance() const;
    // Rejected measurements waiting to become a step (0 when the last one was accepted).
    [[nodiscard]] int pending() const { return static_cast<int>(pending_.size()); }

private:
    struct Pending {
        Pose6 z;
        Cov6 r;
    };
    bool try_step();

    KalmanOptions options_;
    Pose6 x_ = Pose6::Zero();
    Cov6 p_ = Cov6::Identity();
    std::vector<Pending> pending_;
};

}  // namespace mogao::selfcal
