// SPDX-License-Identifier: Apache-2.0
// Chessboard corners and their projector positions by local homographies (local_homography.h).
#include "appliance/procam/local_homography.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace mogao::procam {

namespace {

ProjectorCorner fit_corner(const DecodedPixels& decoded, cv::Point2f corner, const HomographyOptions& o) {
    ProjectorCorner out;
    const int cx = static_cast<int>(std::lround(corner.x));
    const int cy = static_cast<int>(std::lround(corner.y));
    std::vector<cv::Point2f> camera;
    std::vector<cv::Point2f> projector;
    for (int y = std::max(0, cy - o.half_window_px); y <= std::min(decoded.projector.rows - 1, cy + o.half_window_px);
         ++y) {
        const auto* row = decoded.projector.ptr<cv::Vec2i>(y);
        for (int x = std::max(0, cx - o.half_window_px);
             x <= std::min(decoded.projector.cols - 1, cx + o.half_window_px); ++x) {
            if (row[x][0] < 0) continue;
            camera.emplace_back(static_cast<float>(x) - corner.x, static_cast<float>(y) - corner.y);
            projector.emplace_back(static_cast<float>(row[x][0]), static_cast<float>(row[x][1]));
        }
    }
    out.pixels = static_cast<int>(camera.size());
    if (out.pixels < o.min_pixels) return out;
    // Centre the projector side too: RANSAC's threshold stays in pixels, the numbers stay small.
    const cv::Point2f origin = projector[projector.size() / 2];
    for (cv::Point2f& p : projector) p -= origin;
    std::vector<unsigned char> mask;
    const cv::Mat h = o.ransac_px > 0
                          ? cv::findHomography(camera, projector, cv::RANSAC, o.ransac_px, mask, 2000, 0.999)
                          : cv::findHomography(camera, projector, 0);
    if (h.empty()) return out;
    out.inliers = mask.empty() ? out.pixels : static_cast<int>(std::count(mask.begin(), mask.end(), 1));
    if (out.inliers < o.min_pixels) return out;
    // The corner is the window's origin: H (0, 0, 1) = the last column.
    const double w = h.at<double>(2, 2);
    if (std::abs(w) < 1e-12) return out;
    out.position = cv::Point2f(static_cast<float>(h.at<double>(0, 2) / w) + origin.x,
                               static_cast<float>(h.at<double>(1, 2) / w) + origin.y);
    out.valid = std::isfinite(out.position.x) && std::isfinite(out.position.y);
    return out;
}

}  // namespace

std::vector<cv::Point3f> board_points(const BoardSpec& board) {
    if (board.columns < 2 || board.columns > 64 || board.rows < 2 || board.rows > 64) {
        throw std::invalid_argument("board: inner corners " + std::to_string(board.columns) + "x" +
                                    std::to_string(board.rows) + " must be within 2..64 per side");
    }
    if (!(board.square_mm > 0.0 && board.square_mm <= 10000.0)) {
        throw std::invalid_argument("board: square_mm must be in (0, 10000]");
    }
    std::vector<cv::Point3f> points;
    for (int r = 0; r < board.rows; ++r) {
        for (int c = 0; c < board.columns; ++c) {
            points.emplace_back(static_cast<float>(c * board.square_mm), static_cast<float>(r * board.square_mm), 0.0f);
        }
    }
    return points;
}

std::optional<std::vector<cv::Point2f>> find_board_corners(const cv::Mat& grey, const BoardSpec& board) {
    std::vector<cv::Point2f> corners;
    const cv::Size pattern(board.columns, board.rows);
    if (!cv::findChessboardCorners(grey, pattern, corners,
                                   cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE)) {
        return std::nullopt;
    }
    cv::cornerSubPix(grey, corners, cv::Size(5, 5), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-3));
    return corners;
}

std::vector<ProjectorCorner> projector_corners(const DecodedPixels& decoded,
                                               const std::vector<cv::Point2f>& camera_corners,
                                               const HomographyOptions& options) {
    if (options.half_window_px < 2 || options.half_window_px > 200) {
        throw std::invalid_argument("projector_corners: half_window_px must be within 2..200");
    }
    if (options.min_pixels < 4) throw std::invalid_argument("projector_corners: min_pixels must be >= 4");
    if (!(options.ransac_px >= 0.0)) throw std::invalid_argument("projector_corners: ransac_px must be >= 0");
    std::vector<ProjectorCorner> out;
    out.reserve(camera_corners.size());
    for (const cv::Point2f& c : camera_corners) out.push_back(fit_corner(decoded, c, options));
    return out;
}

}  // namespace mogao::procam
