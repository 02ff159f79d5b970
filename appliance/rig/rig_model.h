// SPDX-License-Identifier: Apache-2.0
// The rig description (rigs/*.toml, rig_file.h): a cylindrical screen, its projectors and cameras with their poses
// and intrinsics, and the errors the calibration is told them with (RigPrior). It is also the site file's format
// (docs/on-site-calibration.md): the installation as measured, read by the on-site calibration. What the simulated
// camera makes of it (light, noise, ground truth) is the virtual rig's (virtual_rig.h), which is laboratory code;
// this header and rig_file.h are what a product may link.
//
// Frames, units, pixel-centre and lens conventions are the virtual rig's (virtual_rig.h's header comment): screen
// frame in metres with +y up the cylinder's axis and -z toward the middle of the arc; devices yaw/pitch/roll as in
// ViewerPose; image positions with pixel (x, y) covering [x, x + 1) x [y, y + 1); OpenCV's Brown-Conrady
// distortion (k1, k2, p1, p2, k3).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/pixel_rect.h"

namespace mogao::rig {

struct RigScreen {
    double radius_m = 3.0;
    double arc_deg = 150.0;  // (0, 360]
    double bottom_m = 0.8;
    double top_m = 2.3;
    // A screen that is only roughly a cylinder (fabric bowed between its frame, a shell's tolerance):
    // the distance from the axis is radius_m + bulge_m cos(pi theta / arc) sin(pi (h - bottom) /
    // (top - bottom)), so the frame (arc ends, bottom and top edges) is on the cylinder and the middle
    // is bulge_m away from it (positive: away from the viewer). [-0.02, 0.02] x radius_m; 0 = a cylinder.
    // The calibration is not told: it assumes the cylinder (rigs/bulge.toml).
    double bulge_m = 0.0;
    // A screen that is not matte (virtual_rig.h's header comment, "Screen gain"): its data sheet's peak gain
    // (luminance over a matte screen's, [1, 3]; 1 = matte, Lambertian) and half-gain angle (degrees off the peak
    // where the luminance is half the peak's, [10, 90]). The calibration is not told.
    double gain = 1.0;
    double half_gain_angle_deg = 40.0;
    // Screen-to-screen light: the screen's reflectance for one bounce of the light it throws onto itself
    // (virtual_rig.h's header comment, "Interreflection"), [0, 1]; 0 = none. The calibration is not told.
    double interreflection = 0.0;
};

struct RigPose {
    Eigen::Vector3d position_m{0.0, 1.6, 0.0};  // screen frame
    double yaw_deg = 0.0;
    double pitch_deg = 0.0;
    double roll_deg = 0.0;
};

// Pinhole intrinsics in pixels, principal point in image positions (pixel centre at +0.5).
struct RigIntrinsics {
    double fx_px = 1000.0;
    double fy_px = 1000.0;
    double cx_px = 0.0;
    double cy_px = 0.0;
    std::array<double, 5> distortion{};  // k1, k2, p1, p2, k3 (OpenCV order)
};

struct RigProjector {
    std::string id;
    ImageSize resolution{1920, 1080};
    RigIntrinsics intrinsics;  // distortion: |k1|, |k2|, |k3| <= 1, |p1|, |p2| <= 0.1, one-to-one (checked)
    RigPose pose;
    std::array<double, 3> gamma{2.2, 2.2, 2.2};       // per channel, (0, 10]
    double black_level = 0.002;                       // fraction of full white at signal 0, [0, 1)
    std::array<double, 3> brightness{1.0, 1.0, 1.0};  // full white per channel, (0, 100]
    double falloff = 0.0;                             // lens fall-off at half the diagonal, [0, 0.45]
    double blur_px = 0.0;  // defocus: Gaussian sigma in projector pixels, [0, 10] (header comment)
    // Where the lens's distortion is centred, in projector pixels from the principal point (x right, y down;
    // each within a quarter of the image's side): a lens whose shift moved its distortion off the optical axis, a
    // displacement no principal point or OpenCV coefficient expresses exactly (virtual_rig.h's header comment).
    Eigen::Vector2d distortion_centre_px{0.0, 0.0};
    // What the calibration is told, not the simulation: the projector's lens as measured on the bench (a
    // `mogao-calibrate procam` file; `procam` in the file, resolved against the file's folder), which replaces
    // its data sheet's throw ratio and lens shift in the prior. Empty: none.
    std::filesystem::path procam;
};

struct RigCamera {
    ImageSize resolution{1280, 720};
    RigIntrinsics intrinsics;
    RigPose pose;
    double exposure = 1.0;       // (0, 100]
    double gain = 1.0;           // (0, 100]
    bool auto_exposure = false;  // true: each image is metered (see the header comment), exposure not locked
    double read_noise = 0.003;   // standard deviation of the signal, fraction of full scale, [0, 0.5]
    double shot_noise = 0.0;     // signal-dependent part, see the header comment, [0, 0.5]
    double blur_sigma_px = 0.7;  // Gaussian blur, camera pixels, [0, 20]
    int bits = 8;                // quantisation, 1..16
    int supersample = 1;         // point samples per pixel side, 1..4
    double vignetting = 0.0;     // light lost at rho = 1 (header comment), [0, 0.45]
    // Motion-JPEG frames (a webcam's MJPEG mode): each quantised image is JPEG-compressed at this quality
    // (libjpeg-turbo, 4:2:0) and decoded back, as a USB camera's frames reach the host; 1..100, 0 = raw
    // frames. Needs bits = 8 (JPEG's baseline samples).
    int mjpeg_quality = 0;
    // Timing: the share of the first frame after the shown patterns change that still holds the previous ones'
    // light, [0, 1] (an exposure that straddles the flip, or with 1 a frame the driver queued before it). Only
    // the pattern source sees it (autocal::RigPatternSource, which drops that frame when told to, as the site's
    // camera source drops --drop-frames); CameraSimulator::capture films one pattern set. 0: none.
    double straddle = 0.0;
    std::uint64_t seed = 1;
};

// What the calibration is told about the rig, as errors added to the truth: where the installer
// measured the camera, how well the camera intrinsics are known (a chessboard calibration), what
// the projectors' data sheets say.
struct RigPrior {
    Eigen::Vector3d camera_position_error_m{0.0, 0.0, 0.0};
    Eigen::Vector3d camera_angle_error_deg{0.0, 0.0, 0.0};  // yaw, pitch, roll
    double camera_focal_error = 0.0;                        // relative error of fx, fy
    // What a chessboard calibration leaves in the rest of the camera's intrinsics: the principal point's
    // error in camera pixels (x, y; |each| <= a quarter of the image's side) and the distortion
    // coefficients' errors (k1, k2, p1, p2, k3, OpenCV order, added to the truth's; |each| <= 1).
    Eigen::Vector2d camera_principal_point_error_px{0.0, 0.0};
    std::array<double, 5> camera_distortion_error{};
    double projector_focal_error = 0.0;  // relative error of the projectors' fx, fy
    double screen_radius_error_m = 0.0;  // the screen's radius as the installer was told it
    double screen_arc_error_deg = 0.0;   // and its arc
    // The heights of the screen's bottom and top edges as measured with a tape (metres, added to the truth's;
    // |each| <= 0.1 x the screen's height): a common error shifts the screen along its axis, a different one
    // changes its height and so the scale the calibration takes from it (docs/calibration.md, "Rig files").
    double screen_bottom_error_m = 0.0;
    double screen_top_error_m = 0.0;
    // The screen's data sheet (added to the truth's RigScreen::gain and half_gain_angle_deg; the told values stay
    // within their ranges): a gain screen's lobe as the calibration is told it.
    double screen_gain_error = 0.0;
    double screen_half_gain_angle_error_deg = 0.0;
};

struct VirtualRig {
    std::string name;
    RigScreen screen;
    std::vector<RigProjector> projectors;  // 1..16
    RigCamera camera;                      // camera 0: the one the calibration films with
    std::vector<RigCamera> more_cameras;   // cameras 1..7 (rig file: [[cameras]] after the first)
    double ambient = 0.01;                 // linear light everywhere on the screen, [0, 10]
    // Where the ground truth's light is seen from (a gain screen looks different from every place; a matte one
    // does not): a visitor's eye, screen frame, inside the cylinder. The camera films from its own pose.
    Eigen::Vector3d viewer_m{0.0, 1.6, 0.0};
    RigPrior prior;
};

// Checks every field's range, that the devices are inside the cylinder and that projectors' distortion
// keeps their image one-to-one. Throws std::invalid_argument naming the field and its limit.
void validate_rig(const VirtualRig& rig);

// How many cameras the rig has (1 + more_cameras).
[[nodiscard]] std::size_t camera_count(const VirtualRig& rig);

// The same room filmed by camera `i` (0..camera_count - 1): a copy whose `camera` is that camera, so
// that CameraSimulator(seen_by(rig, i)) forms camera i's images (each camera sees the same light on
// the same screen). Throws std::out_of_range naming i and the count.
[[nodiscard]] VirtualRig seen_by(const VirtualRig& rig, std::size_t i);

// Rotation device -> screen frame (columns: the device's x right, y down, z forward in the screen
// frame) for the yaw/pitch/roll convention above.
[[nodiscard]] Eigen::Matrix3d device_to_screen(const RigPose& pose);

// The Brown-Conrady model (header comment): distorted normalised coordinates of ray (x, y, 1), and the
// ray (z = 1) of distorted normalised coordinates (fixed-point inverse, to 1e-14 or 200 steps).
[[nodiscard]] Eigen::Vector2d distort(const std::array<double, 5>& k, double x, double y);
[[nodiscard]] Eigen::Vector2d undistort(const std::array<double, 5>& k, double xd, double yd);

// The normalised radius of projector p's image corner farthest from its distortion's centre (the principal point
// moved by distortion_centre_px); a projector's distortion is validated (one-to-one) out to 1.2 times it, and
// ground truth is given only within that.
[[nodiscard]] double corner_radius(const RigProjector& p);

// A projection lens's Brown-Conrady coefficients (k1, k2, p1, p2, k3) lie within +-these.
inline constexpr std::array<double, 5> kProjectorDistortionLimits{1.0, 1.0, 0.1, 0.1, 1.0};

// The first of 101 evenly spaced normalised radii in [0, r_max] where the radial map
// r (1 + k1 r^2 + k2 r^4 + k3 r^6) of coefficients k does not increase (d/dr <= 0: two rays would share an
// image position), or nullopt where it increases throughout.
[[nodiscard]] std::optional<double> distortion_fold_radius(const std::array<double, 5>& k, double r_max);

namespace detail {
// Throws std::invalid_argument "rig: FIELD must be LIMIT" (the rig's one error form).
void check(bool ok, const std::string& field, const std::string& limit);
// check() that v is finite and in [lo, hi], naming the value.
void check_range(double v, double lo, double hi, const std::string& field);
}  // namespace detail

}  // namespace mogao::rig
