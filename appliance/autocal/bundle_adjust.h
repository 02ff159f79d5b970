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
// The camera's intrinsics (BundleOptions::refine_camera_intrinsics: fx with the prior's aspect, cx, cy,
// k1, k2) are unknowns too, as in the uncalibrated-camera registration of Sajadi & Majumder 2009
// ("Markerless view-independent registration of multiple distorted projectors on extruded surfaces
// using an uncalibrated camera", IEEE TVCG 15(6)), where the screen's known boundary (its top and
// bottom curves, its ends) determines the camera's focal length with its pose; here the rays are
// re-derived from the camera's image positions at every evaluation, so the projectors' correspondences
// (each projector a pinhole: the camera's ray errors bend its points off any pinhole, through the
// camera-projector baseline on the curved screen) add their evidence. Gauge (Triggs et al. 2000,
// section 9): the screen's known cylinder, heights and ends fix the frame, scale and the rotation about
// the axis, so no parameter is left free by a symmetry; the camera's aspect ratio, skew (0), p1, p2 and
// k3 stay the prior's; what the data barely separate (principal point against a small rotation, focal
// length against distance) is held by a weak Gaussian prior on each intrinsic (CameraIntrinsicsSigma,
// a chessboard's uncertainty), and reported: per-parameter standard deviations from the inverse of
// the normal matrix and its condition number after scaling to unit diagonal (BundleResult).
//
// Minimised (Levenberg-Marquardt, Marquardt 1963, forward-difference Jacobian in double):
//   sum over correspondences of |(project_k(X(camera, ray)) - measured) / sigma_i|^2 / s_k^2
//   + sum over edge points of (distance on the screen of X(camera, ray) from its edge)^2 / sigma_e^2
//   + sum over refined camera intrinsics of ((value - prior's) / prior sigma)^2
// with X(camera, ray) = forward intersection of the camera ray with the cylinder; project_k the
// pinhole x = fx X'/Z' + cx, y = fx * aspect Y'/Z' + cy, or with the projector's lens distortion
// (BundleOptions::refine_projector_distortion, device_image) x = fx xd + cx, y = fx * aspect yd + cy with
// (xd, yd) OpenCV's distorted (X'/Z', Y'/Z') (aspect fy/fx of the prior fixed, image
// positions with pixel centres at +0.5, X' = R_k^T (X - position_k)); sigma_i per point and axis
// (a decoded block of b pixels: b / sqrt(12), the uniform distribution's; a phase-refined position: its own,
// phase_shift.h); s_k and sigma_e are the
// measured residual rms of the previous round (maximum likelihood for Gaussian noise);
// correspondences beyond 4x the median residual of their projector, and with refine_screen edge points beyond 4x
// the median distance of all edge points, are dropped between rounds.
// Threads: the Jacobian's columns and the cost's blocks run on OpenCV's pool (cv::parallel_for_, every core
// unless cv::setNumThreads says otherwise); each writes its own column or block, so the result does not depend
// on the number of threads.
#pragma once

#include <limits>
#include <vector>

#include <Eigen/Core>

#include "appliance/autocal/autocal.h"

namespace mogao::autocal {

enum class ScreenEdge { top, bottom, left_end, right_end };

// An edge point: its undistorted camera ray (camera frame, z = 1) and the edge it lies on; with its
// camera image position (pixel centres at +0.5; NaN: unknown) the ray follows the camera's
// intrinsics as they are refined (BundleOptions::refine_camera_intrinsics).
struct EdgeObservation {
    Eigen::Vector3d ray;
    ScreenEdge edge = ScreenEdge::top;
    Eigen::Vector2d image{std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
};

// One projector's correspondences: undistorted camera rays (camera frame, z = 1) and the
// projector image positions they were decoded to (pixel centres at +0.5). `camera_px`, when given
// (as many as rays), holds the camera image positions the rays came from: the adjustment then
// re-derives the rays from the camera's current intrinsics (undistorted as OpenCV does).
struct ProjectorObservations {
    std::vector<Eigen::Vector3d> rays;
    std::vector<Eigen::Vector2d> projector;
    std::vector<Eigen::Vector2d> sigma_px;   // per point and axis: its uncertainty (empty: 1 px each)
    std::vector<Eigen::Vector2d> camera_px;  // empty: the rays are fixed
};

struct BundleOptions {
    bool refine_camera = true;  // false: the camera pose stays, only projectors move (edges unused)
    // The cylinder's radius and arc too (with the camera; the heights bottom_m / top_m stay as measured and fix
    // the scale): for a screen whose radius and arc are known only roughly. The 3D points follow the fitted
    // cylinder; its curvature is seen through the camera-projector baselines, its ends through the edges.
    bool refine_screen = false;
    // On a told cylinder (without refine_screen), its top edge's height too (ScreenModel::top_m; with the camera,
    // like refine_screen): the bottom edge stays as the gauge (both edges moved together is the camera and the
    // projectors moved). The lit top edge and the projectors' correspondences (through the camera-projector
    // baselines) tell the span. With refine_screen the heights fix the scale and stay.
    bool refine_heights = false;
    // The screen's bow too (ScreenModel::bow_m; with the camera, like refine_screen): the 3D points then
    // follow the bowed surface along the camera rays, and the projectors' rays tell its depth (stereo).
    bool refine_bow = false;
    // The camera's focal length, principal point and radial distortion k1, k2 too (with the camera's pose;
    // the aspect ratio, p1, p2 and k3 stay the prior's), each pulled to the prior by `camera_sigma`. Needs the
    // observations' camera image positions (camera_px, EdgeObservation::image).
    bool refine_camera_intrinsics = false;
    CameraIntrinsicsSigma camera_sigma;
    // Per projector (empty: none): its lens distortion k1, k2, p1, p2 free too (OpenCV's model about its principal
    // point, autocal.h; k3 stays the starting model's). Four more columns per projector; no prior pulls them.
    std::vector<bool> refine_projector_distortion;
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
    double edge_rms_m = 0.0;        // of the edge points kept (inliers), metres on the screen
    int edge_inliers = 0;           // edge points kept (with refine_screen, those beyond 4x the median are dropped)
    // Conditioning at the solution, from the normal matrix N = J^T J of the whitened residuals (prior
    // included): standard deviations sqrt(diag(N^-1)) of the camera's fx, cx, cy (px), k1, k2 when
    // refined (else empty), and the condition number of N after scaling it to unit diagonal (its
    // largest over its smallest eigenvalue; large: some combination of parameters is barely seen).
    std::vector<double> camera_intrinsics_sigma;
    double condition_number = 0.0;
};

// `projectors` are the starting models (intrinsics and pose); observations[k] belong to
// projectors[k]. Throws std::invalid_argument when the sizes disagree or a projector has fewer
// than 10 correspondences.
[[nodiscard]] BundleResult bundle_adjust(const ScreenModel& screen, const DeviceModel& camera,
                                         const std::vector<DeviceModel>& projectors,
                                         const std::vector<EdgeObservation>& edges,
                                         const std::vector<ProjectorObservations>& observations,
                                         const BundleOptions& options = {});

// A device's image position (pixel centres at +0.5) of point q in its own frame (OpenCV's camera frame,
// q.z() > 0; the caller checks), through its lens distortion (OpenCV's Brown-Conrady model about the
// principal point, autocal.h): (fx xd + cx, fy yd + cy). Without distortion the pinhole, computed as
// before it had any. NaN with distortion where the ray is beyond twice the normalised radius of the image's
// farthest corner (there the polynomial may fold back into the image).
[[nodiscard]] Eigen::Vector2d device_image(const DeviceModel& d, const Eigen::Vector3d& q);

// The ray (device frame, z = 1) of image position (x, y): the distortion inverted by OpenCV's fixed-point
// iteration (undistortPoints) to 1e-14; the pinhole's ray without distortion.
[[nodiscard]] Eigen::Vector3d device_ray(const DeviceModel& d, double x, double y);

// The screen point (x, y, z) of an edge or correspondence: camera ray (camera frame) -> cylinder.
// NaN when the ray misses.
[[nodiscard]] Eigen::Vector3d ray_on_screen(const ScreenModel& screen, const DeviceModel& camera,
                                            const Eigen::Vector3d& ray);

}  // namespace mogao::autocal
