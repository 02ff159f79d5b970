// SPDX-License-Identifier: Apache-2.0
// Tests only: where an independent camera model, OpenCV's projectPoints with the rig camera's pose and lens, puts a
// point of the screen frame in the camera's image (image positions, pixel centre +0.5 as the rig's; OpenCV's matrix
// has the centre at integers, hence the half-pixel shifts).
#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/calib3d.hpp>

#include "appliance/rig/virtual_rig.h"

namespace mogao::rig {

inline cv::Point2d opencv_camera_image(const RigCamera& cam, const Eigen::Vector3d& world) {
    const Eigen::Matrix3d r_sc = device_to_screen(cam.pose).transpose();
    const Eigen::Vector3d t = -r_sc * cam.pose.position_m;
    cv::Matx33d rm;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) rm(i, j) = r_sc(i, j);
    cv::Vec3d rvec;
    cv::Rodrigues(rm, rvec);
    const cv::Matx33d kmat(cam.intrinsics.fx_px, 0, cam.intrinsics.cx_px - 0.5, 0, cam.intrinsics.fy_px,
                           cam.intrinsics.cy_px - 0.5, 0, 0, 1);
    std::vector<cv::Point2d> image;
    cv::projectPoints(std::vector<cv::Point3d>{{world.x(), world.y(), world.z()}}, rvec, cv::Vec3d(t.x(), t.y(), t.z()),
                      kmat, cam.intrinsics.distortion, image);
    return image[0] + cv::Point2d(0.5, 0.5);
}

}  // namespace mogao::rig
