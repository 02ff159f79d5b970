// SPDX-License-Identifier: Apache-2.0
// The virtual rig: a cylindrical screen (optionally bowed, RigScreen::bulge_m), N projectors and one
// or more cameras (VirtualRig::camera and more_cameras; seen_by), simulated well enough to
// calibrate against, with the ground truth a real rig never gives (docs/calibration.md, "The
// virtual rig"). It is the reference the camera-based calibration (appliance/autocal) is measured
// against, so it shares no geometry code with it: every formula here is written out again.
//
// Frames and units. Screen frame = CylinderScreen's (common/view_request.h): metres, origin on the
// cylinder axis at floor level, +y up along the axis, -z toward the middle of the arc. A screen
// point is (theta, h): theta in radians measured from -z toward +x (left to right for a viewer
// inside), h in metres; its position is (r sin theta, h, -r cos theta). The screen spans
// theta in [-arc/2, arc/2], h in [bottom_m, top_m] (a bowed screen's point (theta, h) is at its own
// distance from the axis, RigScreen::bulge_m, in the same direction). Content (u, v), normalised as in
// common/projector_calibration.h: u = (theta + arc/2) / arc, v = (top - h) / (top - bottom).
//
// Devices (projectors, camera) are pinholes at `position_m` with yaw/pitch/roll as in ViewerPose:
// yaw about +y (0 looks along -z, positive turns left), then pitch about the device's right axis
// (positive looks up), then roll about its forward axis (positive turns the image clockwise as
// seen by the device). Device image: x right, y down, z forward (OpenCV's camera frame).
// Image positions are continuous with pixel (x, y) covering [x, x + 1) x [y, y + 1), so its centre
// is at (x + 0.5, y + 0.5) (projector_calibration.h); principal points use the same convention
// (OpenCV's matrices put the centre at integers: cx_opencv = cx - 0.5).
// Lens distortion (cameras and projectors): OpenCV's Brown-Conrady model, coefficients (k1, k2, p1, p2, k3)
// on normalised coordinates about the principal point (for a projector the lens-shifted one): a ray
// (x, y, 1) in the device frame reaches image position (fx xd + cx, fy yd + cy) with
// xd = x (1 + k1 r^2 + k2 r^4 + k3 r^6) + 2 p1 x y + p2 (r^2 + 2 x^2),
// yd = y (1 + k1 r^2 + k2 r^4 + k3 r^6) + p1 (r^2 + 2 y^2) + 2 p2 x y, r^2 = x^2 + y^2 (Brown 1966;
// OpenCV calib3d "Camera Calibration and 3D Reconstruction", cv::projectPoints). An image position's
// ray is the model inverted by fixed-point iteration (as cv::undistortPoints) to 1e-14.
// A projector's distortion must keep its image one-to-one out to 1.2 times its corners' radius
// (validate_rig), so that every image position has one ray. A projector's distortion may be centred off its
// principal point (RigProjector::distortion_centre_px = (dx, dy), c = (dx / fx, dy / fy)): the ray (x, y, 1)
// then reaches the distorted normalised position c + D(x - c, y - c), D the model above. Brown's decentring
// terms (p1, p2) are this offset's leading part; the rest (third order in c) no OpenCV coefficient expresses.
// Screen gain (RigScreen::gain = g, half_gain_angle_deg = b): the light a screen point sends toward an
// observer is a matte screen's times G = g 2^(-(alpha / b)^2), alpha the angle between the direction to the
// observer and the projector's ray mirrored about the cylinder's normal there (a Gaussian lobe about the
// mirror direction whose peak and half-peak angle are the data sheet's; g = 1: G = 1, matte). The camera
// sees it from its own pose, the ground truth from VirtualRig::viewer_m.
// Interreflection (RigScreen::interreflection = rho): the screen lights itself. Cut into patches about
// 0.1 m square (screen_light.h), each patch's light leaving it matte (the mean of its direct light) adds
// rho sum_j F_ij L_j to patch i, F_ij = cos_i cos_j A_j / (pi d_ij^2) the form factor of a small patch
// (Cohen & Wallace, "Radiosity and Realistic Image Synthesis", 1993, ch. 4; every pair of points of a
// cylinder's inside sees the other); one bounce, interpolated bilinearly between patch centres, seen matte.
//
// Light (linear, relative to a projector's full white = 1): projector k at signal s in [0, 1]
// (per channel c) puts F_k(x, y) * brightness_k[c] * (black + (1 - black) * s^gamma_k[c]) on the
// screen point its pixel (x, y) lands on, independent of distance and incidence (pixel-density
// fall-off is outside the model, as in appliance/warp/composite.h); light of all projectors adds,
// plus `ambient`. F_k is the lens's fall-off (vignetting), radial about the principal point:
// F = 1 - falloff_k * min(rho^2, 2), rho = distance from (cx, cy) / half the image's diagonal (the
// leading term of the cos^4 law's expansion, 1 - 2 tan^2 phi, with its strength a free parameter:
// projector optics are not a plain pinhole; ANSI/INFOCOMM 3M-2011 reports the corner-to-centre
// ratio a data sheet calls uniformity, e.g. 85 % ~ falloff 0.15). Black light passes the same lens.
// Defocus (RigProjector::blur_px): the light of projector k's image (after its response, before the
// fall-off) is convolved with a Gaussian of standard deviation blur_px projector pixels (OpenCV's
// GaussianBlur, kernel +-4 sigma, on the image padded by defocus_margin pixels of no light): the image's
// outermost pixel rows are dimmed by up to half, and the light they lose spreads past the image's edge onto the
// screen, as a defocused lens spreads it.
// Camera vignetting (RigCamera::vignetting = v): the light reaching camera pixel (x, y) (its centre) is
// multiplied by V = 1 - v min(rho^2, 2), rho = distance from the principal point / half the camera
// image's diagonal: the same radial law as the projectors' fall-off (the leading term of cos^4), so v is
// the light lost at a corner when the principal point is at the image's centre (v = 0.2: 20 %).
// The camera is monochrome with a flat spectral response: it sees the mean of the three channels,
// integrated over each pixel by `supersample`^2 point samples, blurred by a Gaussian of
// `blur_sigma_px` (after the vignetting), scaled by exposure * gain, with Gaussian noise of standard deviation
// sqrt(read_noise^2 + shot_noise^2 * value), clipped to [0, 1] and quantised to `bits`.
// Motion-JPEG (RigCamera::mjpeg_quality = q > 0, bits = 8): the quantised frame, grey on R, G and B, is
// compressed by libjpeg-turbo (common/jpeg_codec.h: TurboJPEG's tjCompress2 with its defaults, 4:2:0, the
// ITU-T T.81 Annex K tables scaled to quality q, the fast integer DCT) and decoded back, as a USB camera's MJPEG
// frames reach the host: 8 x 8 blocks, ringing at sharp edges, fine detail quantised away.
// Auto-exposure (camera.auto_exposure, what a webcam does unless told otherwise): before the noise,
// each image is rescaled so that its mean is kAutoExposureTarget of full scale, whatever the
// exposure, so images of different patterns are not comparable (a calibration must refuse it).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "appliance/rig/rig_model.h"
#include "common/pixel_rect.h"

namespace mogao::rig {

struct ScreenPoint {
    double theta_rad = 0.0;
    double h_m = 0.0;
};

class ScreenBounce;

// Ground truth: where the ray through projector k's image position (x, y) lands on the screen, or
// nullopt when it misses the screen (beyond the arc or the heights).
[[nodiscard]] std::optional<ScreenPoint> projector_to_screen(const VirtualRig& rig, int k, double x, double y);

// Ground truth, the other way: the image position of projector k that lands on screen point p, or
// nullopt when p is behind the projector or outside its image [0, W) x [0, H) grown by `margin_px` on every side
// (defocus_margin: where a defocused projector's light still reaches).
[[nodiscard]] std::optional<Eigen::Vector2d> screen_to_projector(const VirtualRig& rig, int k, ScreenPoint p,
                                                                 double margin_px = 0.0);
// How far past its image's edge a defocused projector's light reaches, in its pixels: ceil(4 blur_px), the
// Gaussian's kernel radius (0 for a sharp projector).
[[nodiscard]] int defocus_margin(const RigProjector& p);

// The screen's point (theta, h) in the screen frame (a bowed screen's at its own distance from the axis).
[[nodiscard]] Eigen::Vector3d screen_position(const RigScreen& screen, ScreenPoint p);

// Camera vignetting V at camera image position (x, y) (header comment; 1 on the principal point).
[[nodiscard]] double camera_vignetting(const RigCamera& c, double x, double y);

// Ground truth: projector k's relative light at image position (x, y) (F in the header comment; 1
// on the principal point, in (0, 1]).
[[nodiscard]] double projector_falloff(const RigProjector& p, double x, double y);

// Content (u, v) of a screen point and back (formulas in the header comment).
[[nodiscard]] Eigen::Vector2d content_of(const RigScreen& screen, ScreenPoint p);
[[nodiscard]] ScreenPoint screen_of(const RigScreen& screen, Eigen::Vector2d uv);

inline constexpr double kAutoExposureTarget = 0.45;

// Forms camera images of the rig. Building it traces every camera sample once (ray -> screen ->
// each projector's pixel); capture() then only looks up the projectors' images.
class CameraSimulator {
public:
    explicit CameraSimulator(const VirtualRig& rig);  // validates the rig

    // signals[k]: projector k's input signal, CV_32FC1 (grey, the same on R, G and B) or CV_32FC3
    // (RGB), resolution of projector k, values clipped to [0, 1]; an empty Mat = projector off
    // (black level only). `frame` seeds the noise (same frame = same image). Returns the camera
    // image, CV_32FC1 in [0, 1], camera resolution. Throws std::invalid_argument for wrong sizes.
    [[nodiscard]] cv::Mat1f capture(const std::vector<cv::Mat>& signals, std::uint64_t frame) const;

    [[nodiscard]] const VirtualRig& rig() const { return rig_; }
    // The camera's manual exposure (what a locked camera lets the calibration set, e.g. a long
    // exposure for black levels); (0, 100], else std::invalid_argument. Has no effect while
    // auto-exposure is on (the metering overrides it).
    void set_exposure(double exposure);
    // Fraction of projector k's 8x8-pixel blocks that some camera sample sees (ground truth coverage).
    [[nodiscard]] double camera_coverage(int k) const;

private:
    VirtualRig rig_;
    int samples_w_ = 0;
    int samples_h_ = 0;
    std::vector<std::uint8_t> on_screen_;  // per sample
    // Per projector, per sample: its pixel's index in the image padded by defocus_margin on every side (the
    // image itself for a sharp projector), or -1.
    std::vector<std::vector<std::int32_t>> hit_;
    std::vector<cv::Mat1f> dark_light_;  // per defocused projector: defocused_light of the dark projector
    // Screen gain toward the camera (RigScreen::gain != 1): per projector, per camera pixel, G at the pixel's centre.
    std::vector<std::vector<float>> gain_;
    // Interreflection (RigScreen::interreflection > 0): the patches, each camera pixel's screen point (its centre's
    // ray on the cylinder, clamped to the screen) and each patch centre's pixel of every projector (or -1).
    std::shared_ptr<const ScreenBounce> bounce_;
    std::vector<ScreenPoint> pixel_point_;
    std::vector<std::vector<Eigen::Vector2f>> patch_pixel_;
    void trace_screen_light();  // fills gain_, bounce_, pixel_point_ and patch_pixel_ (constructor)
    // The light leaving every patch (direct light, matte) for the projectors' signals.
    [[nodiscard]] std::vector<double> patch_light(const std::vector<cv::Mat>& signals,
                                                  const std::vector<cv::Mat1f>& blurred) const;
};

}  // namespace mogao::rig
