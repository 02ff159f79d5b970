// SPDX-License-Identifier: Apache-2.0
// Robust 6-DOF pose of a pinhole device from screen points and where the device sees (or shows)
// them, intrinsics fixed: RANSAC (Fischler & Bolles 1981) with OpenCV's solvePnPRansac for the
// consensus set, then Gauss-Newton with Huber weights (Huber 1964; iteratively reweighted least
// squares, Holland & Welsch 1977) over that set and every point within 3x the RANSAC threshold.
//
// Frames as in appliance/autocal/autocal.h: a DeviceModel's rotation maps device -> screen frame,
// position in metres in the screen frame; image positions have pixel (x, y)'s centre at
// (x + 0.5, y + 0.5). Here the device's image points are given *normalised*: ((x - cx) / fx,
// (y - cy) / fy), after undoing any lens distortion, so one solver serves camera and projectors;
// `focal_px` converts thresholds and residuals to the device's pixels.
// The pose change (Pose6, pose_kalman.h) of `moved` against `reference`: w = log(R_ref^T R_moved)
// (device frame), d = p_moved - p_ref (screen frame); the fit's covariance uses the same
// parameters, sigma^2 (J^T W J)^-1 with sigma the weighted residual rms (prior rows included).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "appliance/autocal/autocal.h"
#include "appliance/selfcal/pose_kalman.h"

namespace mogao::selfcal {

struct RobustPoseOptions {
    double ransac_threshold_px = 2.5;  // reprojection error of a RANSAC inlier, device pixels, > 0
    int ransac_iterations = 300;
    double huber_k = 1.345;  // Huber's constant in units of the robust residual sd (95 % efficiency)
    int iterations = 12;     // Gauss-Newton iterations
    int min_points = 12;     // fewer points or inliers: no fit
    // Prior on the position: pseudo-observations (p - p_start) / sd, each worth one pixel of
    // residual per sd (0: none). A rotation about a far point and a shift look alike in the image;
    // the prior settles that ambiguous direction on "rotation" (a knocked mount mostly turns)
    // and leaves the directions the image determines to the data.
    double prior_position_sd_m = 0.0;
};

struct PoseFit {
    bool ok = false;
    autocal::DeviceModel model;  // `start` with the fitted rotation and position
    int inliers = 0;
    double rms_px = 0.0;  // Huber-weighted residual rms of the inliers, device pixels
    Cov6 covariance = Cov6::Identity();
    std::vector<char> inlier;  // per point
};

// points: screen frame (m); normalised: the device's normalised image coordinates of each point.
// `start` gives the intrinsics (fx for `focal_px`) and the initial pose. Returns ok = false when
// there are too few points or inliers; throws std::invalid_argument when the sizes differ.
[[nodiscard]] PoseFit fit_pose_robust(const autocal::DeviceModel& start, const std::vector<Eigen::Vector3d>& points,
                                      const std::vector<Eigen::Vector2d>& normalised,
                                      const RobustPoseOptions& options = {});

[[nodiscard]] Pose6 pose_delta(const autocal::DeviceModel& reference, const autocal::DeviceModel& moved);
[[nodiscard]] autocal::DeviceModel apply_delta(const autocal::DeviceModel& reference, const Pose6& delta);

// Normalised coordinates of a point in the screen frame seen by a pinhole pose (no distortion);
// NaN behind the device.
[[nodiscard]] Eigen::Vector2d project_normalised(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& position,
                                                 const Eigen::Vector3d& point);

}  // namespace mogao::selfcal
