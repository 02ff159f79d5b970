// SPDX-License-Identifier: Apache-2.0
// Camera calibration from photos of a chessboard (Zhang, "A flexible new technique for camera
// calibration", PAMI 2000, as implemented by OpenCV calibrateCamera).
//
// Corners: cv::findChessboardCornersSB (Duda & Frese, "Accurate detection and localization of
// checkerboard corners for calibration", BMVC 2018), which finds the inner corners to sub-pixel
// accuracy itself. Model: fx, fy, cx, cy and k1, k2, p1, p2 with k3 fixed at 0 (a webcam lens
// at arm's length does not need k3, and freeing it over-fits a handful of photos); the result
// has 5 coefficients, k3 = 0. Pixel convention: OpenCV's (camera_intrinsics.h).
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "appliance/tracker/camera_intrinsics.h"

namespace mogao {

struct ChessboardSpec {
    int inner_columns = 9;    // inner corners per row, [2, 64]
    int inner_rows = 6;       // inner corners per column, [2, 64]
    double square_m = 0.025;  // side of one square, (0, 1] m
};

struct CalibrationResult {
    CameraIntrinsics intrinsics;
    double rms_px = 0.0;                // RMS reprojection error over all corners of all used images
    std::vector<std::string> used;      // file names the board was found in
    std::vector<std::string> rejected;  // "<file>: <reason>"
};

// A calibration that cannot be made: fewer than 3 usable images, images of different sizes.
struct CalibrationError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Throws std::invalid_argument for a bad spec, CalibrationError as above. Unreadable images and
// images without the board are listed in `rejected`, not fatal.
[[nodiscard]] CalibrationResult calibrate_chessboard(const std::vector<std::filesystem::path>& images,
                                                     const ChessboardSpec& spec);

// The images (*.png, *.pgm, *.jpg, *.jpeg) directly in `folder`, sorted by name. Throws
// CalibrationError naming the folder if it is missing.
[[nodiscard]] std::vector<std::filesystem::path> list_images(const std::filesystem::path& folder);

}  // namespace mogao
