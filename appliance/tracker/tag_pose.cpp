// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/tag_pose.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

namespace mogao {

std::vector<TagPose> solve_tag_pose(const std::array<Eigen::Vector2d, 4>& corners, const CameraIntrinsics& camera,
                                    double tag_size_m) {
    if (!(tag_size_m > 0.0 && tag_size_m <= 10.0)) {
        throw std::invalid_argument("solve_tag_pose: tag size " + std::to_string(tag_size_m) + " m outside (0, 10]");
    }
    for (const auto& c : corners) {
        if (!c.allFinite()) throw std::invalid_argument("solve_tag_pose: a corner is not finite");
    }
    validate(camera);
    const double h = tag_size_m / 2.0;
    // IPPE_SQUARE wants its object points in this fixed order: (-h, h), (h, h), (h, -h), (-h, -h).
    // In the tag frame (y up) those are AprilTag's corners 3, 2, 1, 0.
    const std::vector<cv::Point3d> object{{-h, h, 0}, {h, h, 0}, {h, -h, 0}, {-h, -h, 0}};
    std::vector<cv::Point2d> image;
    // -0.5: AprilTag's pixel centres are at +0.5, OpenCV's (the intrinsics') at 0.
    for (int i : {3, 2, 1, 0}) {
        image.emplace_back(corners[static_cast<std::size_t>(i)].x() - 0.5,
                           corners[static_cast<std::size_t>(i)].y() - 0.5);
    }
    const cv::Matx33d k(camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
    std::vector<cv::Mat> rvecs;
    std::vector<cv::Mat> tvecs;
    cv::Mat errors;
    cv::solvePnPGeneric(object, image, k, camera.distortion, rvecs, tvecs, false, cv::SOLVEPNP_IPPE_SQUARE,
                        cv::noArray(), cv::noArray(), errors);
    std::vector<TagPose> poses;
    for (std::size_t i = 0; i < rvecs.size(); ++i) {
        cv::Matx33d r;
        cv::Rodrigues(rvecs[i], r);
        TagPose p;
        for (int a = 0; a < 3; ++a) {
            for (int b = 0; b < 3; ++b) p.rotation(a, b) = r(a, b);
            p.translation_m(a) = tvecs[i].at<double>(a);
        }
        p.reprojection_rms_px = errors.empty() ? 0.0 : errors.at<double>(static_cast<int>(i));
        poses.push_back(p);
    }
    // OpenCV sorts IPPE's solutions by error already; keep that order explicit.
    std::stable_sort(poses.begin(), poses.end(),
                     [](const TagPose& a, const TagPose& b) { return a.reprojection_rms_px < b.reprojection_rms_px; });
    return poses;
}

double rotation_angle_deg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
    const double c = std::clamp(((a.transpose() * b).trace() - 1.0) / 2.0, -1.0, 1.0);
    return std::acos(c) * 180.0 / std::numbers::pi;
}

}  // namespace mogao
