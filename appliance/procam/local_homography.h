// SPDX-License-Identifier: Apache-2.0
// The chessboard's corners in the camera and, through the decoded Gray code, in the projector by
// local homographies: D. Moreno and G. Taubin, "Simple, Accurate, and Robust Projector-Camera
// Calibration", 3DIMPVT 2012, section 3. Around each camera corner, the decoded camera pixels of a
// window map to their projector positions; on the planar board that map is a homography up to the
// lenses' distortion, which is nearly constant over a small window. The homography fitted to the
// window, applied to the sub-pixel camera corner, gives the corner's projector position with
// sub-pixel accuracy even though every decoded position is a whole projector pixel.
//
// Our fit: RANSAC (a pixel whose code is wrong, from scattered light or a stripe edge, is an
// outlier), then least squares on the inliers with Levenberg-Marquardt refinement (cv::findHomography;
// Hartley & Zisserman, "Multiple View Geometry", 2nd ed., 4.7-4.8), on pixel coordinates centred on
// the corner. Moreno & Taubin fit by least squares alone.
//
// Pixel convention: OpenCV's, in both images (pixel centre at integer coordinates): what
// cv::findChessboardCorners returns and cv::calibrateCamera expects.
#pragma once

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "appliance/procam/gray_decode.h"

namespace mogao::procam {

struct BoardSpec {
    int columns = 0;  // inner corners per row
    int rows = 0;     // inner corners per column
    double square_mm = 0.0;
};

// The board's corners in its own frame (z = 0, millimetres), row by row: (c s, r s, 0), the order
// cv::findChessboardCorners returns them in. Throws std::invalid_argument unless columns and rows are
// in 2..64 and square_mm in (0, 10000].
[[nodiscard]] std::vector<cv::Point3f> board_points(const BoardSpec& board);

// The inner corners in a CV_8U image lit by the projector's white, sub-pixel (cv::cornerSubPix,
// 11x11 window), or nullopt if the whole board is not found.
[[nodiscard]] std::optional<std::vector<cv::Point2f>> find_board_corners(const cv::Mat& grey, const BoardSpec& board);

struct HomographyOptions {
    int half_window_px = 24;  // the window is (2 h + 1)^2 camera pixels around the corner
    int min_pixels = 50;      // decoded pixels the window needs, else the corner is dropped
    double ransac_px = 1.0;   // RANSAC inlier distance in projector pixels; 0: least squares only
};

struct ProjectorCorner {
    cv::Point2f position;  // projector image, pixels (OpenCV convention)
    int pixels = 0;        // decoded camera pixels in the window
    int inliers = 0;       // of them, inliers of the fit
    bool valid = false;
};

// One entry per camera corner. Throws std::invalid_argument unless half_window_px is in 2..200,
// min_pixels >= 4 and ransac_px >= 0.
[[nodiscard]] std::vector<ProjectorCorner> projector_corners(const DecodedPixels& decoded,
                                                             const std::vector<cv::Point2f>& camera_corners,
                                                             const HomographyOptions& options = {});

}  // namespace mogao::procam
