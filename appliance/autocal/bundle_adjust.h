// SPDX-License-Identifier: Apache-2.0
// Joint refinement of the camera pose and every projector's pinhole model on all the
// calibration's observations, with the screen as a cylinder (autocal.h, step 4): bundle
// adjustment (Triggs, McLauchlan, Hartley, Fitzgibbon 2000, "Bundle adjustment - a modern
// synthesis") in the form of Sajadi & Majumder 2010 ("Auto-calibration of cylindrical
// multi-projector systems", IEEE VR): the 3D point of a correspondence is not a free unknown but
// the camera ray's intersection with the cylinder, so the camera pose, the projectors' intrinsics
// and their poses are the only unknowns (with BundleOptions::refine_screen also the cylinder's radius
// and arc); the screen's lit edges tie the pose to the screen's
// ends and heights (the cylinder alone leaves a rotation about its axis and a shift along it).
//
// Minimised (Levenberg-Marquardt, Marquardt 1963, forward-difference Jacobian in double):
//   sum over correspondences of |(project_k(X(camera, ray)) - measured) / sigma_i|^2 / s_k^2
//   + sum over edge points of (distance on the screen of X(camera, ray) from its edge)^2 / sigma_e^2
// with X(camera, ray) = forward intersection of the camera ray with the cylinder; project_k the
// pinhole x = fx X'/Z' + cx, y = fx * aspect Y'/Z' + cy (aspect fy/fx of the prior fixed, image
// positions with pixel centres at +0.5, X' = R_k^T (X - position_k)); sigma_i per point and axis
// (a decoded block of b pixels: b / sqrt(12), the uniform distribution's; a phase-refined position: its own,
// phase_shift.h); s_k and sigma_e are the
// measured residual rms of the previous round (maximum likelihood for Gaussian noise);
// correspondences beyond 4x the median residual of their projector are dropped between rounds.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "appliance/autocal/autocal.h"

namespace mogao::autocal {

enum class ScreenEdge { top, bottom, left_end, right_end };

// An edge point: its undistorted camera ray (camera frame, z = 1) and the edge it lies on.
struct EdgeObservation {
    Eigen::Vector3d ray;
    ScreenEdge edge = ScreenEdge::top;
};

// One projector's correspondences: undistorted camera rays (camera frame, z = 1) and the
// projector image positions they were decoded to (pixel centres at +0.5).
struct ProjectorObservations {
    std::vector<Eigen::Vector3d> rays;
    std::vector<Eigen::Vector2d> projector;
    std::vector<Eigen::Vector2d> sigma_px;  // per point and axis: its uncertainty (empty: 1 px each)
};

struct BundleOptions {
    bool refine_camera = true;  // false: the camera pose stays, only projectors move (edges unused)
    // The cylinder's radius and arc too (with the camera; the heights bottom_m / top_m stay as measured and fix
    // the scale): for a screen whose radius and arc are known only roughly. The 3D points follow the fitted
    // cylinder; its curvature is seen through the camera-projector baselines, its ends through the edges.
    bool refine_screen = false;
    // The screen's bow too (ScreenModel::bow_m; with the camera, like refine_screen): the 3D points then
    // follow the bowed surface along the camera rays, and the projectors' rays tell its depth (stereo).
    bool refine_bow = false;
    int rounds = 2;           // LM runs, outliers dropped between them
    int max_iterations = 40;  // LM iterations per round
};

struct BundleResult {
    ScreenModel screen;  // the fitted screen (the given one unless refine_screen)
    DeviceModel camera;
    std::vector<DeviceModel> projectors;
    std::vector<double> rms_px;     // per projector, correspondence residual of the last round (inliers), px
    std::vector<double> rms_sigma;  // the same in units of each point's sigma_px (about 1 for a good fit)
    std::vector<int> inliers;       // per projector
    double edge_rms_m = 0.0;
};

// `projectors` are the starting models (intrinsics and pose); observations[k] belong to
// projectors[k]. Throws std::invalid_argument when the sizes disagree or a projector has fewer
// than 10 correspondences.
[[nodiscard]] BundleResult bundle_adjust(const ScreenModel& screen, const DeviceModel& camera,
                                         const std::vector<DeviceModel>& projectors,
                                         const std::vector<EdgeObservation>& edges,
                                         const std::vector<ProjectorObservations>& observations,
                                         const BundleOptions& options = {});

// The screen point (x, y, z) of an edge or correspondence: camera ray (camera frame) -> cylinder.
// NaN when the ray misses.
[[nodiscard]] Eigen::Vector3d ray_on_screen(const ScreenModel& screen, const DeviceModel& camera,
                                            const Eigen::Vector3d& ray);

}  // namespace mogao::autocal
