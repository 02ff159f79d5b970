// SPDX-License-Identifier: Apache-2.0
// Kalman filter over a pose change with a validation gate and step detection (pose_kalman.h).
#include "appliance/selfcal/pose_kalman.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/LU>

namespace mogao::selfcal {

namespace {

bool finite(const Eigen::MatrixXd& m) { return m.allFinite(); }

constexpr double kStepGateScale = 4.0;

}  // namespace

PoseKalman::PoseKalman(const KalmanOptions& o) : options_(o) {
    const auto fail = [](const std::string& what) { throw std::invalid_argument("PoseKalman: " + what); };
    if (!(o.rotation_walk_rad >= 0.0) || !std::isfinite(o.rotation_walk_rad)) fail("rotation_walk_rad >= 0");
    if (!(o.position_walk_m >= 0.0) || !std::isfinite(o.position_walk_m)) fail("position_walk_m >= 0");
    if (!(o.initial_rotation_sd_rad > 0.0) || !(o.initial_position_sd_m > 0.0)) fail("initial sds > 0");
    if (!(o.gate_chi2 > 0.0)) fail("gate_chi2 > 0");
    if (o.step_frames < 1) fail("step_frames >= 1");
    reset();
}

void PoseKalman::reset() {
    Cov6 p = Cov6::Zero();
    const double r2 = options_.initial_rotation_sd_rad * options_.initial_rotation_sd_rad;
    const double p2 = options_.initial_position_sd_m * options_.initial_position_sd_m;
    p.diagonal() << r2, r2, r2, p2, p2, p2;
    reset(Pose6::Zero(), p);
}

void PoseKalman::reset(const Pose6& x, const Cov6& p) {
    x_ = x;
    p_ = 0.5 * (p + p.transpose());
    pending_.clear();
}

void PoseKalman::predict(double dt_s) {
    if (!std::isfinite(dt_s) || dt_s < 0.0) {
        throw std::invalid_argument("PoseKalman::predict: dt_s must be finite and >= 0 (got " + std::to_string(dt_s) +
                                    ")");
    }
    const double qr = options_.rotation_walk_rad * options_.rotation_walk_rad * dt_s;
    const double qp = options_.position_walk_m * options_.position_walk_m * dt_s;
    for (int i = 0; i < 3; ++i) p_(i, i) += qr;
    for (int i = 3; i < 6; ++i) p_(i, i) += qp;
}

KalmanUpdate PoseKalman::update(const Pose6& z, const Cov6& r) {
    if (!finite(z) || !finite(r)) throw std::invalid_argument("PoseKalman::update: non-finite measurement");
    const Cov6 s = p_ + r;
    const Eigen::LDLT<Cov6> ldlt(s);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) {
        throw std::invalid_argument("PoseKalman::update: P + R is not positive definite");
    }
    const Pose6 y = z - x_;
    const double d2 = y.dot(ldlt.solve(y));
    if (!(d2 <= options_.gate_chi2)) {
        pending_.push_back({z, r});
        if (static_cast<int>(pending_.size()) > options_.step_frames) pending_.erase(pending_.begin());
        return try_step() ? KalmanUpdate::step_accepted : KalmanUpdate::rejected;
    }
    pending_.clear();
    const Eigen::Matrix<double, 6, 6> k = ldlt.solve(p_).transpose();  // P S^-1 (P, S symmetric)
    x_ += k * y;
    const Cov6 a = Cov6::Identity() - k;
    p_ = a * p_ * a.transpose() + k * r * k.transpose();
    p_ = 0.5 * (p_ + p_.transpose());
    return KalmanUpdate::accepted;
}

bool PoseKalman::try_step() {
    if (static_cast<int>(pending_.size()) < options_.step_frames) return false;
    Cov6 info = Cov6::Zero();
    Pose6 weighted = Pose6::Zero();
    for (const Pending& m : pending_) {
        const Cov6 ri = m.r.inverse();
        info += ri;
        weighted += ri * m.z;
    }
    const Cov6 cov = info.inverse();
    const Pose6 mean = cov * weighted;
    for (const Pending& m : pending_) {
        const Pose6 y = m.z - mean;
        // Looser than the validation gate: frames with visitors scatter more than their fit's
        // covariance says, and a real step must still be taken among them.
        if (!(y.dot(m.r.ldlt().solve(y)) <= kStepGateScale * options_.gate_chi2)) return false;
    }
    reset(mean, cov);
    return true;
}

double PoseKalman::significance() const { return x_.dot(p_.ldlt().solve(x_)); }

}  // namespace mogao::selfcal
