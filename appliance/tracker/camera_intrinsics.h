// SPDX-License-Identifier: Apache-2.0
// Pinhole camera intrinsics with OpenCV's distortion model, and the calibration files they come
// from.
//
// Model (OpenCV calib3d, "Camera Calibration and 3D Reconstruction"): a point (X, Y, Z) in the
// camera frame (x right, y down, z forward along the optical axis, metres) projects to
// u = fx * x'' + cx, v = fy * y'' + cy, where x'' y'' are x = X/Z, y = Y/Z distorted by
// k1 k2 p1 p2 [k3 [k4 k5 k6 [s1 s2 s3 s4 [tx ty]]]]. Pixel convention: OpenCV's, the CENTRE of
// the top-left pixel is (0, 0). AprilTag's corners put it at (0.5, 0.5) (tag_detector.h), and
// solve_tag_pose converts. An ideal 800x600 camera has cx = 399.5, cy = 299.5.
//
// Files (read_intrinsics picks the format by extension):
//   .json      {"image_width": 800, "image_height": 600, "fx": 700.0, "fy": 700.0, "cx": 399.5,
//               "cy": 299.5, "distortion": [k1, k2, p1, p2, k3]}  ("distortion" optional, 0, 4, 5,
//               8, 12 or 14 values; other keys such as "rms_reprojection_px" are ignored)
//   .yml .yaml .xml   OpenCV FileStorage as written by OpenCV's calibration sample and
//               `cv::FileStorage << ...`: image_width, image_height, camera_matrix (3x3),
//               distortion_coefficients (1xN or Nx1, optional)
// write_intrinsics writes the JSON form.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <vector>

namespace mogao {

struct CameraIntrinsics {
    int width = 0;  // image size the calibration holds for, pixels, [1, 8192]
    int height = 0;
    double fx = 0.0;  // focal lengths, pixels, > 0
    double fy = 0.0;
    double cx = 0.0;  // principal point, pixels, OpenCV convention, inside [-0.5, width - 0.5] etc.
    double cy = 0.0;
    std::vector<double> distortion;  // OpenCV order; empty = none
};

// A calibration file that cannot be read, parsed or validated; the message names the file and
// the field and the limit or reason.
struct CalibrationFileError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Throws std::invalid_argument naming the field and its limit (the ranges above; all finite).
void validate(const CameraIntrinsics& intrinsics);

// Same camera at another resolution (binning or scaling): u' = (u + 0.5) * s - 0.5 per axis, so
// that pixel areas, not pixel centres, line up. Throws std::invalid_argument for a size < 1.
[[nodiscard]] CameraIntrinsics rescale(const CameraIntrinsics& intrinsics, int width, int height);

[[nodiscard]] CameraIntrinsics read_intrinsics(const std::filesystem::path& path);
// Writes the JSON form; rms_px (the calibration's reprojection error) is stored when >= 0.
void write_intrinsics(const std::filesystem::path& path, const CameraIntrinsics& intrinsics, double rms_px = -1.0);

}  // namespace mogao
