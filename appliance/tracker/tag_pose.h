// SPDX-License-Identifier: Apache-2.0
// Tag pose from its four detected corners: both solutions of the planar PnP problem.
//
// Frames (metres):
//   camera  OpenCV's: x right, y down, z forward along the optical axis (camera_intrinsics.h)
//   tag     origin at the tag centre, x to the right and y up of the tag as printed, z out of the
//           printed face (toward whoever looks at it). Corners, in AprilTag order
//           (tag_detector.h): (-s/2, -s/2, 0), (s/2, -s/2, 0), (s/2, s/2, 0), (-s/2, s/2, 0),
//           s = tag size (side of the black border square, tag_bitmap.h).
// A tag held upright facing the camera has rotation diag(1, -1, -1).
//
// Solver: OpenCV solvePnPGeneric with SOLVEPNP_IPPE_SQUARE (Collins & Bartoli, "Infinitesimal
// Plane-based Pose Estimation", IJCV 2014). It returns the two poses that explain a planar square
// seen under perspective; one is usually much better, but for small or nearly frontal tags the
// two mirror each other's tilt with nearly equal error (the planar ambiguity). Choosing between
// them is PoseDisambiguator's job (pose_disambiguator.h).
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "appliance/tracker/camera_intrinsics.h"

namespace mogao {

struct TagPose {
    Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();   // tag frame -> camera frame
    Eigen::Vector3d translation_m = Eigen::Vector3d::Zero();  // tag centre in the camera frame
    double reprojection_rms_px = 0.0;                         // RMS distance of the reprojected to the detected corners
};

// The (one or) two IPPE poses, lowest reprojection error first. `corners` as TagDetector reports
// them (AprilTag order, pixel centres at +0.5); they are shifted by -0.5 to OpenCV's convention of
// the intrinsics before solving, and distortion is handled by OpenCV. Throws std::invalid_argument for
// a tag size outside (0, 10] m, non-finite corners or invalid intrinsics.
[[nodiscard]] std::vector<TagPose> solve_tag_pose(const std::array<Eigen::Vector2d, 4>& corners,
                                                  const CameraIntrinsics& camera, double tag_size_m);

// The angle (degrees, [0, 180]) of the rotation taking a to b: acos((trace(a^T b) - 1) / 2).
[[nodiscard]] double rotation_angle_deg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b);

}  // namespace mogao
