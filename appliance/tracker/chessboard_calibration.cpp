// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/chessboard_calibration.h"

#include <algorithm>
#include <cctype>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "drivers/camera/image_file.h"

namespace mogao {

std::vector<std::filesystem::path> list_images(const std::filesystem::path& folder) {
    std::error_code ec;
    if (!std::filesystem::is_directory(folder, ec)) throw CalibrationError(folder.string() + ": not a directory");
    std::vector<std::filesystem::path> out;
    for (const auto& entry : std::filesystem::directory_iterator(folder)) {
        std::string ext = entry.path().extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(),
                       [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
        if (entry.is_regular_file() && (ext == ".png" || ext == ".pgm" || ext == ".jpg" || ext == ".jpeg")) {
            out.push_back(entry.path());
        }
    }
    std::sort(out.begin(), out.end());
    return out;
}

CalibrationResult calibrate_chessboard(const std::vector<std::filesystem::path>& images, const ChessboardSpec& spec) {
    if (spec.inner_columns < 2 || spec.inner_columns > 64 || spec.inner_rows < 2 || spec.inner_rows > 64) {
        throw std::invalid_argument("ChessboardSpec: inner corners " + std::to_string(spec.inner_columns) + "x" +
                                    std::to_string(spec.inner_rows) + " outside [2, 64] per side");
    }
    if (!(spec.square_m > 0.0 && spec.square_m <= 1.0)) {
        throw std::invalid_argument("ChessboardSpec: square " + std::to_string(spec.square_m) + " m outside (0, 1]");
    }
    const cv::Size pattern(spec.inner_columns, spec.inner_rows);
    std::vector<cv::Point3f> board;
    for (int r = 0; r < spec.inner_rows; ++r) {
        for (int c = 0; c < spec.inner_columns; ++c) {
            board.emplace_back(static_cast<float>(c * spec.square_m), static_cast<float>(r * spec.square_m), 0.0f);
        }
    }
    CalibrationResult result;
    std::vector<std::vector<cv::Point3f>> object_points;
    std::vector<std::vector<cv::Point2f>> image_points;
    cv::Size size;
    for (const auto& path : images) {
        auto image = read_gray_image(path);
        if (!image) {
            result.rejected.push_back(image.error().message);
            continue;
        }
        const cv::Size this_size(image->width, image->height);
        if (size.area() == 0) size = this_size;
        if (this_size != size) {
            throw CalibrationError(path.string() + ": " + std::to_string(this_size.width) + "x" +
                                   std::to_string(this_size.height) + " differs from the first image's " +
                                   std::to_string(size.width) + "x" + std::to_string(size.height));
        }
        const cv::Mat mat(image->height, image->width, CV_8UC1, image->pixels.data());
        std::vector<cv::Point2f> corners;
        if (!cv::findChessboardCornersSB(mat, pattern, corners, cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_ACCURACY)) {
            result.rejected.push_back(path.string() + ": no " + std::to_string(spec.inner_columns) + "x" +
                                      std::to_string(spec.inner_rows) + " chessboard found");
            continue;
        }
        object_points.push_back(board);
        image_points.push_back(std::move(corners));
        result.used.push_back(path.string());
    }
    if (image_points.size() < 3) {
        throw CalibrationError("chessboard calibration: the board was found in " + std::to_string(image_points.size()) +
                               " image(s), at least 3 are needed (tilted views from different angles)");
    }
    cv::Mat k;
    cv::Mat dist;
    std::vector<cv::Mat> rvecs;
    std::vector<cv::Mat> tvecs;
    result.rms_px = cv::calibrateCamera(object_points, image_points, size, k, dist, rvecs, tvecs, cv::CALIB_FIX_K3);
    CameraIntrinsics& c = result.intrinsics;
    c.width = size.width;
    c.height = size.height;
    c.fx = k.at<double>(0, 0);
    c.fy = k.at<double>(1, 1);
    c.cx = k.at<double>(0, 2);
    c.cy = k.at<double>(1, 2);
    dist = dist.reshape(1, 1);
    c.distortion.assign(dist.ptr<double>(0), dist.ptr<double>(0) + dist.cols);
    validate(c);
    return result;
}

}  // namespace mogao
