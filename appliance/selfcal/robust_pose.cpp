// SPDX-License-Identifier: Apache-2.0
// RANSAC + Huber Gauss-Newton pose of a pinhole device (robust_pose.h).
#include "appliance/selfcal/robust_pose.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>

namespace mogao::selfcal {

namespace {

Eigen::Matrix3d exp_so3(const Eigen::Vector3d& w) {
    const double a = w.norm();
    if (a < 1e-15) return Eigen::Matrix3d::Identity();
    return Eigen::AngleAxisd(a, w / a).toRotationMatrix();
}

Eigen::Vector3d log_so3(const Eigen::Matrix3d& r) {
    const Eigen::AngleAxisd aa(r);
    return aa.angle() * aa.axis();
}

// Consensus set by OpenCV's RANSAC PnP in normalised coordinates (identity camera matrix).
std::vector<char> ransac_inliers(const autocal::DeviceModel& start, const std::vector<Eigen::Vector3d>& points,
                                 const std::vector<Eigen::Vector2d>& normalised, const RobustPoseOptions& o,
                                 autocal::DeviceModel& pose) {
    std::vector<cv::Point3d> obj;
    std::vector<cv::Point2d> img;
    for (std::size_t i = 0; i < points.size(); ++i) {
        obj.emplace_back(points[i].x(), points[i].y(), points[i].z());
        img.emplace_back(normalised[i].x(), normalised[i].y());
    }
    // World (screen) -> camera: R_wc = R^T, t = -R^T p.
    const Eigen::Matrix3d rwc = start.rotation.transpose();
    const Eigen::Vector3d t = -rwc * start.position_m;
    cv::Mat rm(3, 3, CV_64F);
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) rm.at<double>(r, c) = rwc(r, c);
    cv::Mat rvec;
    cv::Rodrigues(rm, rvec);
    cv::Mat tvec = (cv::Mat_<double>(3, 1) << t.x(), t.y(), t.z());
    std::vector<int> idx;
    const bool ok =
        cv::solvePnPRansac(obj, img, cv::Mat::eye(3, 3, CV_64F), cv::Mat(), rvec, tvec, true, o.ransac_iterations,
                           static_cast<float>(o.ransac_threshold_px / start.fx_px), 0.999, idx, cv::SOLVEPNP_ITERATIVE);
    std::vector<char> in(points.size(), 0);
    if (!ok) return in;
    cv::Rodrigues(rvec, rm);
    Eigen::Matrix3d r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) r(i, j) = rm.at<double>(i, j);
    pose.rotation = r.transpose();
    pose.position_m = -r.transpose() * Eigen::Vector3d(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
    for (int i : idx) in[static_cast<std::size_t>(i)] = 1;
    return in;
}

struct Residuals {
    Eigen::VectorXd r;  // 2 per point, device pixels
};

Residuals residuals(const autocal::DeviceModel& d, const Eigen::Matrix3d& rot, const Eigen::Vector3d& pos,
                    const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector2d>& normalised,
                    const std::vector<int>& use) {
    Residuals out;
    out.r.resize(static_cast<Eigen::Index>(2 * use.size()));
    for (std::size_t j = 0; j < use.size(); ++j) {
        const auto i = static_cast<std::size_t>(use[j]);
        const Eigen::Vector2d e = (project_normalised(rot, pos, points[i]) - normalised[i]);
        out.r(static_cast<Eigen::Index>(2 * j)) = e.x() * d.fx_px;
        out.r(static_cast<Eigen::Index>(2 * j + 1)) = e.y() * d.fy_px;
    }
    return out;
}

// Robust scale: 1.4826 x the median absolute residual (per coordinate).
double robust_sigma(const Eigen::VectorXd& r) {
    std::vector<double> a(static_cast<std::size_t>(r.size()));
    for (Eigen::Index i = 0; i < r.size(); ++i) a[static_cast<std::size_t>(i)] = std::abs(r(i));
    std::nth_element(a.begin(), a.begin() + static_cast<long>(a.size() / 2), a.end());
    return std::max(1e-3, 1.4826 * a[a.size() / 2]);
}

}  // namespace

Eigen::Vector2d project_normalised(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& position,
                                   const Eigen::Vector3d& point) {
    const Eigen::Vector3d q = rotation.transpose() * (point - position);
    if (!(q.z() > 1e-9)) return {std::nan(""), std::nan("")};
    return {q.x() / q.z(), q.y() / q.z()};
}

Pose6 pose_delta(const autocal::DeviceModel& reference, const autocal::DeviceModel& moved) {
    Pose6 d;
    d.head<3>() = log_so3(reference.rotation.transpose() * moved.rotation);
    d.tail<3>() = moved.position_m - reference.position_m;
    return d;
}

autocal::DeviceModel apply_delta(const autocal::DeviceModel& reference, const Pose6& delta) {
    autocal::DeviceModel m = reference;
    m.rotation = reference.rotation * exp_so3(delta.head<3>());
    m.position_m = reference.position_m + delta.tail<3>();
    return m;
}

PoseFit fit_pose_robust(const autocal::DeviceModel& start, const std::vector<Eigen::Vector3d>& points,
                        const std::vector<Eigen::Vector2d>& normalised, const RobustPoseOptions& o) {
    if (points.size() != normalised.size()) throw std::invalid_argument("fit_pose_robust: points and image differ");
    PoseFit fit;
    fit.model = start;
    fit.inlier.assign(points.size(), 0);
    if (static_cast<int>(points.size()) < o.min_points) return fit;
    autocal::DeviceModel pose = start;
    const std::vector<char> consensus = ransac_inliers(start, points, normalised, o, pose);
    // Everything within 3x the threshold of the consensus pose goes to the M-estimator.
    std::vector<int> use;
    for (std::size_t i = 0; i < points.size(); ++i) {
        const Eigen::Vector2d e = project_normalised(pose.rotation, pose.position_m, points[i]) - normalised[i];
        const double px = std::hypot(e.x() * start.fx_px, e.y() * start.fy_px);
        if (consensus[i] || px < 3.0 * o.ransac_threshold_px) use.push_back(static_cast<int>(i));
    }
    if (static_cast<int>(use.size()) < o.min_points) return fit;
    Eigen::Matrix3d rot = pose.rotation;
    Eigen::Vector3d pos = pose.position_m;
    Eigen::Matrix<double, 6, 6> jtwj = Eigen::Matrix<double, 6, 6>::Identity();
    double sigma = 1.0;
    Eigen::VectorXd w;
    for (int it = 0; it < o.iterations; ++it) {
        const Residuals r0 = residuals(start, rot, pos, points, normalised, use);
        sigma = robust_sigma(r0.r);
        w = Eigen::VectorXd::Ones(r0.r.size());
        for (Eigen::Index i = 0; i < r0.r.size(); ++i) {
            const double a = std::abs(r0.r(i)) / sigma;
            if (a > o.huber_k) w(i) = o.huber_k / a;
        }
        Eigen::MatrixXd j(r0.r.size(), 6);
        for (int p = 0; p < 6; ++p) {
            Pose6 step = Pose6::Zero();
            const double h = p < 3 ? 1e-6 : 1e-6;
            step(p) = h;
            const Eigen::Matrix3d rp = rot * exp_so3(step.head<3>());
            const Residuals rr = residuals(start, rp, pos + step.tail<3>(), points, normalised, use);
            j.col(p) = (rr.r - r0.r) / h;
        }
        jtwj = j.transpose() * w.asDiagonal() * j;
        Pose6 g = j.transpose() * (w.asDiagonal() * r0.r);
        if (o.prior_position_sd_m > 0.0) {
            // Rows (p - p_start) / sd: J = I / sd on the position block.
            const double inv = 1.0 / o.prior_position_sd_m;
            jtwj.bottomRightCorner<3, 3>() += Eigen::Matrix3d::Identity() * inv * inv;
            g.tail<3>() += (pos - start.position_m) * inv * inv;
        }
        const Pose6 dx = -jtwj.ldlt().solve(g);
        if (!dx.allFinite()) return fit;
        rot = rot * exp_so3(dx.head<3>());
        pos += dx.tail<3>();
        if (dx.head<3>().norm() < 1e-9 && dx.tail<3>().norm() < 1e-9) break;
    }
    const Residuals rf = residuals(start, rot, pos, points, normalised, use);
    double wsum = 0.0;
    double wr2 = 0.0;
    for (Eigen::Index i = 0; i < rf.r.size(); ++i) {
        wsum += w(i);
        wr2 += w(i) * rf.r(i) * rf.r(i);
    }
    fit.rms_px = std::sqrt(wr2 / std::max(1.0, wsum));
    fit.model.rotation = rot;
    fit.model.position_m = pos;
    fit.covariance = fit.rms_px * fit.rms_px * jtwj.inverse();
    fit.inliers = static_cast<int>(use.size());
    for (int i : use) fit.inlier[static_cast<std::size_t>(i)] = 1;
    fit.ok = fit.covariance.allFinite();
    return fit;
}

}  // namespace mogao::selfcal
