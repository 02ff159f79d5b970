// SPDX-License-Identifier: Apache-2.0
// Projector-camera calibration on the bench from real captures of a chessboard lit by Gray code
// (docs/calibration.md, "Projector intrinsics on the bench"), after D. Moreno and G. Taubin,
// "Simple, Accurate, and Robust Projector-Camera Calibration", 3DIMPVT 2012:
//   1. per capture folder: decode (gray_decode.h), find the board's corners in the white image,
//      their projector positions by local homographies (local_homography.h);
//   2. camera intrinsics and distortion: cv::calibrateCamera on the camera corners (Zhang, "A
//      flexible new technique for camera calibration", IEEE TPAMI 22(11), 2000);
//   3. projector intrinsics and distortion: the same on the projector corners (the projector as an
//      inverse camera);
//   4. the pose: cv::stereoCalibrate, intrinsics fixed or refined (CalibrationOptions).
//
// Conventions (OpenCV's throughout): pixel centre at integer coordinates; K = [fx 0 cx; 0 fy cy;
// 0 0 1]; distortion (k1, k2, p1, p2, k3) of Brown-Conrady as OpenCV applies it; R, T take a point
// from camera coordinates to projector coordinates, X_p = R X_c + T, T in millimetres (the board's
// unit); R is a rotation matrix, row-major in the JSON.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "appliance/procam/gray_decode.h"
#include "appliance/procam/local_homography.h"

namespace mogao::procam {

// One board pose: the corners found in both images (those whose local homography failed dropped).
struct BoardObservation {
    std::string name;  // the capture folder's name
    std::vector<cv::Point3f> board;
    std::vector<cv::Point2f> camera;
    std::vector<cv::Point2f> projector;
    double lit_fraction = 0.0;      // camera pixels over the shadow threshold
    double decoded_fraction = 0.0;  // camera pixels decoded (of all the camera's pixels)
    int corners_dropped = 0;
};

// From a decoded capture and its white image. Throws ProcamError naming `name` if the board is not
// found in the white image, or if fewer than 6 corners have a projector position.
[[nodiscard]] BoardObservation observe_board(const std::string& name, const cv::Mat& white,
                                             const DecodedPixels& decoded, const BoardSpec& board,
                                             const HomographyOptions& options = {});

// The defaults were chosen by leave-one-capture-out on the four real captures (docs/calibration.md,
// "Projector intrinsics on the bench", where the alternatives' figures are): with three or four
// poses of a board held nearly facing the pair, a camera's principal point and a projector's lens
// distortion are not identifiable (free, the projector's k2 comes out near 5 and the held-out
// error doubles), so the camera keeps its principal point at the image centre and radial k1, k2
// (OpenCV's CALIB_FIX_PRINCIPAL_POINT), the projector is a pinhole (as
// appliance/autocal models it), and stereoCalibrate then refines both focal lengths and the
// projector's principal point with the rigid pose between them (Moreno & Taubin's last step).
struct CalibrationOptions {
    int camera_flags = kCameraFlags;          // cv::calibrateCamera flags for the camera
    int projector_flags = kPinholeProjector;  // ... and for the projector
    bool refine_in_stereo = true;  // stereoCalibrate with CALIB_USE_INTRINSIC_GUESS (and both flag sets), else
                                   // CALIB_FIX_INTRINSIC
    static constexpr int kCameraFlags = cv::CALIB_FIX_PRINCIPAL_POINT | cv::CALIB_ZERO_TANGENT_DIST | cv::CALIB_FIX_K3;
    static constexpr int kPinholeProjector =
        cv::CALIB_ZERO_TANGENT_DIST | cv::CALIB_FIX_K1 | cv::CALIB_FIX_K2 | cv::CALIB_FIX_K3;
    static constexpr int kRadialProjector = cv::CALIB_ZERO_TANGENT_DIST | cv::CALIB_FIX_K3;  // k1, k2 free
};

struct Intrinsics {
    ImageSize size;
    cv::Matx33d K;
    std::array<double, 5> dist{};  // k1 k2 p1 p2 k3
};

struct CaptureResidual {
    std::string name;
    int corners = 0;
    double camera_rms_px = 0.0;     // reprojection of the board through the stereo model, camera
    double projector_rms_px = 0.0;  // ... and projector
};

struct ProcamCalibration {
    Intrinsics camera;
    Intrinsics projector;
    cv::Matx33d R;
    cv::Vec3d T;                 // mm
    double rms = 0.0;            // cv::stereoCalibrate's rms over both images, pixels
    double camera_rms = 0.0;     // cv::calibrateCamera's, camera alone
    double projector_rms = 0.0;  // ... projector alone
    std::vector<CaptureResidual> captures;
};

// Needs >= 2 observations. Throws std::invalid_argument otherwise, or for sizes outside 2..16384.
[[nodiscard]] ProcamCalibration calibrate_procam(const std::vector<BoardObservation>& views, ImageSize camera,
                                                 ImageSize projector, const CalibrationOptions& options = {});

// A pose not calibrated with: its board pose from the camera alone (cv::solvePnP with the camera's
// intrinsics), moved into the projector by R, T, projected with the projector's intrinsics and
// distortion, against the projector corners decoded for that pose. Pixels.
struct HeldOutError {
    std::string name;
    int corners = 0;
    double mean_px = 0.0;
    double p95_px = 0.0;
    double max_px = 0.0;
};
[[nodiscard]] HeldOutError held_out_error(const ProcamCalibration& c, const BoardObservation& view);

// Calibrates on all views but one, for each one (>= 3 views).
[[nodiscard]] std::vector<HeldOutError> leave_one_out(const std::vector<BoardObservation>& views, ImageSize camera,
                                                      ImageSize projector, const CalibrationOptions& options = {});

// The calibration file (docs/calibration.md, "The procam file"): format "mogao-procam 1",
// camera.{size, K, dist}, projector.{size, K, dist}, R, T, units "mm", rms, camera_rms,
// projector_rms, captures[{name, corners, camera_rms_px, projector_rms_px}], and held_out[] when
// given. Written atomically.
[[nodiscard]] nlohmann::json procam_json(const ProcamCalibration& c, const std::vector<HeldOutError>& held_out = {});
void write_procam_file(const std::filesystem::path& path, const nlohmann::json& j);

// The projector's intrinsics and distortion from a procam file: what the on-site calibration takes
// as the projector's prior (kiosk/calibrate/procam_command.h, bench_lens_from_procam). Throws
// ProcamError naming the file and the field: unreadable, not JSON, another format, a missing or
// non-numeric field, a size outside 2..16384, fx or fy not positive, or the principal point
// outside the image.
[[nodiscard]] Intrinsics read_procam_projector(const std::filesystem::path& path);

}  // namespace mogao::procam
