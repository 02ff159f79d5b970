// SPDX-License-Identifier: Apache-2.0
// Geometry of the calibration (autocal.h): camera rays, the cylinder, the camera pose from the
// screen's lit edges (step 2) and the projector fit (step 3).
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "appliance/autocal/autocal.h"
#include "appliance/autocal/bundle_adjust.h"

namespace mogao::autocal {

// Unit-free ray directions through camera image positions, undistorted, in the camera frame (z = 1;
// camera.rotation takes them to the screen frame).
[[nodiscard]] std::vector<Eigen::Vector3d> camera_rays(const DeviceModel& camera,
                                                       const std::vector<cv::Point2d>& image);

// The screen's distance from the axis at (theta, h) (ScreenModel: the radius plus the bow inside the
// screen, the radius outside it).
[[nodiscard]] double screen_radius_at(const ScreenModel& screen, double theta, double h);

// The screen point at (theta, h): at screen_radius_at's distance from the axis (screen frame).
[[nodiscard]] Eigen::Vector3d screen_position(const ScreenModel& screen, double theta, double h);

// G (ScreenModel's comment) at screen point (theta, h) for light from `source` seen from `observer` (screen
// frame, metres; the cylinder's normal, the bow's slope left out); 1 on a matte screen.
[[nodiscard]] double screen_gain_at(const ScreenModel& screen, double theta, double h, const Eigen::Vector3d& source,
                                    const Eigen::Vector3d& observer);

// Forward intersection of o + t d with the screen's surface, o inside; nullopt when the ray is
// vertical. A cylinder in closed form; with a bow, Newton steps on the distance from the surface along
// the ray (to 1e-12 m) from the hit of the cylinder of radius R, kept inside the bracket of the cylinders
// of radius R -/+ the bow's largest excursion (bisection where a step would leave it).
[[nodiscard]] std::optional<Eigen::Vector3d> cylinder_hit(const ScreenModel& screen, const Eigen::Vector3d& o,
                                                          const Eigen::Vector3d& d);

// How far on the screen (metres) an edge point may lie from the edge it is assigned to: the last gate of the
// camera pose's edge fit, and select_edges' after the bundle adjustment.
inline constexpr double kEdgeGateM = 0.02;

// A crossing of the lit screen's edge found in the camera image, before it is assigned to an edge.
struct EdgeCandidate {
    cv::Point2d image;           // camera image position, pixel centres at +0.5
    bool vertical_scan = false;  // found scanning a column: on the top or bottom edge, if on any
};

struct EdgeFit {
    DeviceModel camera;
    int points = 0;       // edge points used (inliers)
    int side_points = 0;  // of which on the arc's ends
    double rms_m = 0.0;
    std::vector<EdgeObservation> edges;     // the inliers with the edge each lies on (for bundle_adjust)
    std::vector<EdgeCandidate> candidates;  // every crossing found, inliers or not (for select_edges)
};

// The candidates that lie within `gate_m` metres on the screen of one of its edges as `camera` sees `screen`, each
// with the edge it lies on. fit_camera_pose assigns them with the prior's intrinsics and told screen; with the screen
// fitted, calibrate assigns them again through the refined model: points that the prior's errors put beyond the
// gate are then kept.
[[nodiscard]] std::vector<EdgeObservation> select_edges(const std::vector<EdgeCandidate>& candidates,
                                                        const DeviceModel& camera, const ScreenModel& screen,
                                                        double gate_m);

// Step 2: lit = all projectors white minus all black. Throws CalibrationRefused when the edges are
// too few or the fit is above its gate.
[[nodiscard]] EdgeFit fit_camera_pose(const cv::Mat1f& lit, const CalibrationPrior& prior,
                                      const AutocalOptions& options);

struct ProjectorFit {
    DeviceModel model;
    int points = 0;
    double rms_px = 0.0;
    double rms_sigma = 0.0;  // rms in units of the points' decoding uncertainty
    double mean_view_angle_deg = 0.0;
    ProjectorObservations observations;  // all correspondences (for bundle_adjust)
};

// Step 3 for projector k. Throws CalibrationRefused naming the projector.
[[nodiscard]] ProjectorFit fit_projector(const DeviceModel& camera, const CalibrationPrior& prior, int k,
                                         const std::vector<cv::Point2d>& camera_points,
                                         const std::vector<cv::Point2d>& projector_points,
                                         const std::vector<cv::Point2d>& sigmas, const AutocalOptions& options);

}  // namespace mogao::autocal
