// SPDX-License-Identifier: Apache-2.0
// Projector-camera calibration from board observations (procam_calibration.h).
#include "appliance/procam/procam_calibration.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/calib3d.hpp>

#include "appliance/procam/procam_error.h"
#include "common/file_io.h"

namespace mogao::procam {

namespace {

void check_size(ImageSize s, const char* what) {
    if (s.width < 2 || s.height < 2 || s.width > 16384 || s.height > 16384) {
        throw std::invalid_argument(std::string("calibrate_procam: ") + what + " size must be within 2..16384");
    }
}

std::array<double, 5> dist_of(const cv::Mat& d) {
    std::array<double, 5> out{};
    for (int i = 0; i < 5 && i < static_cast<int>(d.total()); ++i) out[static_cast<std::size_t>(i)] = d.at<double>(i);
    return out;
}

cv::Mat dist_mat(const std::array<double, 5>& d) {
    return cv::Mat(5, 1, CV_64F, const_cast<double*>(d.data())).clone();
}

double calibrate_one(const std::vector<std::vector<cv::Point3f>>& board,
                     const std::vector<std::vector<cv::Point2f>>& image, ImageSize size, int flags, Intrinsics& out) {
    cv::Mat k;
    cv::Mat d;
    std::vector<cv::Mat> rvecs;
    std::vector<cv::Mat> tvecs;
    const double rms = cv::calibrateCamera(board, image, cv::Size(size.width, size.height), k, d, rvecs, tvecs, flags);
    out.size = size;
    out.K = cv::Matx33d(k);
    out.dist = dist_of(d);
    return rms;
}

double percentile(std::vector<double> v, double q) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    const double pos = q * static_cast<double>(v.size() - 1);
    const auto lo = static_cast<std::size_t>(std::floor(pos));
    const std::size_t hi = std::min(lo + 1, v.size() - 1);
    return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

}  // namespace

BoardObservation observe_board(const std::string& name, const cv::Mat& white, const DecodedPixels& decoded,
                               const BoardSpec& board, const HomographyOptions& options) {
    const std::vector<cv::Point3f> points = board_points(board);
    const auto corners = find_board_corners(white, board);
    if (!corners) {
        throw ProcamError(name + ": the " + std::to_string(board.columns) + "x" + std::to_string(board.rows) +
                          " inner corners of the board are not all found in the white image");
    }
    const std::vector<ProjectorCorner> projected = projector_corners(decoded, *corners, options);
    BoardObservation o;
    o.name = name;
    const double pixels = static_cast<double>(decoded.projector.total());
    o.lit_fraction = decoded.lit_pixels / pixels;
    o.decoded_fraction = decoded.decoded_pixels / pixels;
    for (std::size_t i = 0; i < projected.size(); ++i) {
        if (!projected[i].valid) {
            ++o.corners_dropped;
            continue;
        }
        o.board.push_back(points[i]);
        o.camera.push_back((*corners)[i]);
        o.projector.push_back(projected[i].position);
    }
    if (o.board.size() < 6) {
        throw ProcamError(name + ": only " + std::to_string(o.board.size()) +
                          " corners have a decoded projector position (at least 6 needed; is the board lit?)");
    }
    return o;
}

ProcamCalibration calibrate_procam(const std::vector<BoardObservation>& views, ImageSize camera, ImageSize projector,
                                   const CalibrationOptions& options) {
    if (views.size() < 2) throw std::invalid_argument("calibrate_procam: needs at least 2 board poses");
    check_size(camera, "camera");
    check_size(projector, "projector");
    std::vector<std::vector<cv::Point3f>> board;
    std::vector<std::vector<cv::Point2f>> cam;
    std::vector<std::vector<cv::Point2f>> proj;
    for (const BoardObservation& v : views) {
        board.push_back(v.board);
        cam.push_back(v.camera);
        proj.push_back(v.projector);
    }
    ProcamCalibration c;
    c.camera_rms = calibrate_one(board, cam, camera, options.camera_flags, c.camera);
    c.projector_rms = calibrate_one(board, proj, projector, options.projector_flags, c.projector);
    cv::Mat kc(c.camera.K);
    cv::Mat dc = dist_mat(c.camera.dist);
    cv::Mat kp(c.projector.K);
    cv::Mat dp = dist_mat(c.projector.dist);
    cv::Mat r;
    cv::Mat t;
    cv::Mat e;
    cv::Mat f;
    cv::Mat per_view;
    const int flags = options.refine_in_stereo
                          ? cv::CALIB_USE_INTRINSIC_GUESS | options.camera_flags | options.projector_flags
                          : cv::CALIB_FIX_INTRINSIC;
    c.rms = cv::stereoCalibrate(board, cam, proj, kc, dc, kp, dp, cv::Size(camera.width, camera.height), r, t, e, f,
                                per_view, flags,
                                cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200, 1e-9));
    c.camera.K = cv::Matx33d(kc);
    c.camera.dist = dist_of(dc);
    c.projector.K = cv::Matx33d(kp);
    c.projector.dist = dist_of(dp);
    c.R = cv::Matx33d(r);
    c.T = cv::Vec3d(t);
    for (std::size_t i = 0; i < views.size(); ++i) {
        const int row = static_cast<int>(i);
        c.captures.push_back(CaptureResidual{views[i].name, static_cast<int>(views[i].board.size()),
                                             per_view.at<double>(row, 0), per_view.at<double>(row, 1)});
    }
    return c;
}

HeldOutError held_out_error(const ProcamCalibration& c, const BoardObservation& view) {
    cv::Mat rvec;
    cv::Mat tvec;
    if (!cv::solvePnP(view.board, view.camera, cv::Mat(c.camera.K), dist_mat(c.camera.dist), rvec, tvec, false,
                      cv::SOLVEPNP_ITERATIVE)) {
        throw ProcamError(view.name + ": no board pose from the camera corners");
    }
    cv::Matx33d rb;
    cv::Rodrigues(rvec, rb);
    const cv::Matx33d r = c.R * rb;
    const cv::Vec3d t = c.R * cv::Vec3d(tvec) + c.T;
    cv::Mat rv;
    cv::Rodrigues(cv::Mat(r), rv);
    std::vector<cv::Point2f> predicted;
    cv::projectPoints(view.board, rv, cv::Mat(t), cv::Mat(c.projector.K), dist_mat(c.projector.dist), predicted);
    HeldOutError h;
    h.name = view.name;
    h.corners = static_cast<int>(predicted.size());
    std::vector<double> err;
    for (std::size_t i = 0; i < predicted.size(); ++i) err.push_back(cv::norm(predicted[i] - view.projector[i]));
    double sum = 0.0;
    for (double e : err) sum += e;
    h.mean_px = err.empty() ? 0.0 : sum / static_cast<double>(err.size());
    h.p95_px = percentile(err, 0.95);
    h.max_px = err.empty() ? 0.0 : *std::max_element(err.begin(), err.end());
    return h;
}

std::vector<HeldOutError> leave_one_out(const std::vector<BoardObservation>& views, ImageSize camera,
                                        ImageSize projector, const CalibrationOptions& options) {
    if (views.size() < 3) throw std::invalid_argument("leave_one_out: needs at least 3 board poses");
    std::vector<HeldOutError> out;
    for (std::size_t k = 0; k < views.size(); ++k) {
        std::vector<BoardObservation> rest;
        for (std::size_t i = 0; i < views.size(); ++i) {
            if (i != k) rest.push_back(views[i]);
        }
        out.push_back(held_out_error(calibrate_procam(rest, camera, projector, options), views[k]));
    }
    return out;
}

}  // namespace mogao::procam
