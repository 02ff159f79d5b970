// SPDX-License-Identifier: Apache-2.0
// Camera-based geometric calibration of projectors on a cylindrical screen (seed paper
// II.B): Gray-code structured light per projector, the camera's pose from the screen's lit edges,
// a pinhole model per projector fitted to the correspondences, and from it a piecewise-linear warp
// (grid step = knob), smooth blend masks from the measured coverage and a response curve: the
// ScreenCalibration (common/projector_calibration.h) the compositor and the kiosk use.
// Pure maths on camera images: no GL, no hardware. A PatternSource shows images and returns what
// the camera saw (the virtual rig in tests, real projectors and a camera later).
//
// Frames, units and pixel conventions are the virtual rig's (appliance/rig/virtual_rig.h):
// screen frame in metres (+y up the cylinder axis, -z to the middle of the arc), screen points
// (theta, h), content u = (theta + arc/2) / arc, v = (top - h) / (top - bottom); image positions
// with pixel (x, y)'s centre at (x + 0.5, y + 0.5); devices in OpenCV's camera frame (x right,
// y down, z forward); camera distortion in OpenCV's Brown-Conrady model.
//
// Method (docs/calibration.md, "Camera-based calibration"):
//  1. Gray code (Gray 1953, reflected binary; as in Inokuchi, Sato, Matsuda 1984) per projector and
//     axis, each pattern followed by its inverse; a pixel's bit is the sign of pattern - inverse
//     (per-pixel threshold), a pixel counts where white - black exceeds `min_contrast` (shadow
//     mask); bits are captured from the coarsest down and stop at the first one the camera cannot
//     resolve (fewer than `min_bit_fraction` of the pixels with |pattern - inverse| > half the
//     contrast) or at `max_gray_bits`; every image is the mean of `frames_per_pattern` frames. Per camera pixel, bits
//     are taken until its first one below half its contrast; in the reflected Gray code that bit flips at the middle of
//     the pixel's block, so the block's centre is the pixel's position. Each decoded camera pixel (all but at most two
//     of the resolved bits per axis) gives a correspondence: its centre <-> the block's centre, with the block's size /
//     sqrt(12) as its uncertainty (a uniform error over the block). The shadow mask's threshold is also
//     `shadow_noise_sigmas` times the noise of white - black, estimated from the black image, and
//     `shadow_relative` of the projector's own contrast (its 99th percentile).
//  1b. Phase shift (phase_shift.h; Gühring 2001): `phase_shifts` sinusoids per axis refine each pixel whose Gray
//     block is at most half a period to a sub-pixel position with its own uncertainty.
//  2. Camera pose: the lit region of the projectors at full white ends at the screen's edges
//     (projectors overfill them; one projector at a time, lit_screen). Edge points are located to sub-pixel as
//     the crossing of the local half level; Gauss-Newton on the camera's 6 pose parameters minimises the distance,
//     on the screen, of each edge point's ray from the edge it belongs to (h = top/bottom, theta = +-arc/2),
//     from the prior pose, with a weak pull to the prior (the ends fix the yaw about the axis).
//  3. Projector: camera ray of each correspondence -> cylinder -> 3D point; SQPnP with the
//     data-sheet intrinsics for the pose, then Levenberg-Marquardt on focal length, principal point
//     and pose (bundle_adjust.h with the camera fixed), outliers beyond 4x the median dropped.
//  4. Bundle adjustment (bundle_adjust.h; Sajadi & Majumder 2010): camera pose and all projector
//     models together on every correspondence and edge point, the 3D points constrained to the
//     cylinder; with `fit_screen` also its radius and arc (the heights fix the scale), the projector fit
//     gate then applied after it, and the fitted screen checked to be one; without, with `fit_heights`, its top
//     edge's height (the bottom fixes the position, the told radius the scale), the edge gate then applied after
//     it. With
//     `refine_camera_intrinsics` (a trial, kept where it pays) also the camera's focal length, principal point and k1,
//     k2 (Sajadi & Majumder 2009 for an uncalibrated camera on an extruded screen), each camera ray re-derived from its
//     image position; the projector fit gate is then applied after it, and the refined intrinsics are gated
//     (`camera_sigma_gate`, and within 4 prior sigmas of the prior's).
//     With `fit_projector_distortion` (a trial kept per projector where it pays) also each projector's lens
//     distortion k1, k2, p1, p2 (OpenCV's model about its principal point, Brown 1966), after the other trials.
//  5. Warp: grid samples at texel centres (warp_sampling.h) -> fitted projector ray (through its distortion) ->
//  cylinder
//     -> content (u, v), left unclamped past the screen's edges (the blend is 0 there).
//  0. The camera's auto-exposure must be locked (refused otherwise, before any pattern is shown).
//  0b. The camera's timing (camera_timing.h): the previous pattern's share in the first frame after a change,
//     refused above `max_frame_straddle` before the other patterns.
//  6. Blend (linear light; Raskar et al. 1998, "The office of the future", and 1999, "Multi-projector
//     displays using camera-based registration": weights falling with the distance to the edge of each
//     projector's footprint, normalised to sum to 1): w_k = f(d_k) / sum_j f(d_j), d_j = Euclidean
//     distance in projector j's pixels of the screen point from the parts of j's image border that lie
//     on the screen (borders beyond the screen's top, bottom or ends are no overlap edges; the parts are
//     located once per projector, each end found by bisection), 0 outside j's image, f =
//     smoothstep(d / ramp); 0 off the screen. The distance to a fixed closed set is continuous, so the
//     weights are continuous everywhere on the screen (no test that flips from one pixel to the next),
//     C1 along the ramps, sum to 1 wherever a projector lights the screen, ramps only across the overlaps.
//  7. Predicted seam gate: predicted_seam_deviation() of the result above `max_predicted_seam`: refused.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "common/projector_calibration.h"

namespace mogao::autocal {

// The screen: a cylinder about the +y axis (screen frame, virtual_rig.h), optionally bowed between
// its frame. The distance from the axis at (theta, h) is radius_m + sum over m, n in {1, 2} of
// bow_m[2 (m - 1) + (n - 1)] sin(m pi (theta + arc/2) / arc) sin(n pi (h - bottom_m) / (top_m - bottom_m))
// inside the screen, radius_m outside it: the bow vanishes on the frame (arc ends, bottom and top
// edges), where the screen is held, and its first mode (m = n = 1) is a bow of the whole screen, the
// others bows of its halves (the lowest modes of a membrane clamped at its frame). Metres.
// A screen that is not matte, as its data sheet gives it (told, never fitted): its peak gain over a matte
// screen and half-gain angle. The light a device at P throws on screen point x looks from an observer at O
// G = gain 2^-(alpha / half_gain_angle)^2 times as bright as from a matte screen, alpha the angle between the
// direction x -> O and the ray P -> x mirrored about the cylinder's normal (a Gaussian lobe about the mirror
// direction, peak and half-peak angle as the data sheet's; gain 1: matte, G = 1). The colour step divides the
// camera's view of each projector by its G toward the camera and compensates the light as G toward `viewer_m`
// shows it (colour_calibration.h): a gain screen is seamless from one place, the visitors' (screen frame).
struct ScreenModel {
    double radius_m = 3.0;
    double arc_deg = 150.0;
    double bottom_m = 0.8;
    double top_m = 2.3;
    std::array<double, 4> bow_m{};            // 0: a cylinder; fitted with AutocalOptions::fit_bow
    double gain = 1.0;                        // [1, 3]
    double half_gain_angle_deg = 40.0;        // [10, 90]
    Eigen::Vector3d viewer_m{0.0, 1.6, 0.0};  // where the seams are judged from, inside the cylinder
    // The screen's reflectance for its own light (rho, [0, 1)): what one bounce between its patches throws back
    // (screen_bounce.h), measured by the colour step; 0 before it, and on a screen that does not light itself.
    double interreflection = 0.0;
};

// A projector's relative light over its image: its lens's fall-off (vignetting), the part of
// Majumder & Stevens' (TVCG 10(2) 2004) spatial luminance variation that lies within one projector,
// measured by the colour step (colour_calibration.h). F(x, y) = c . (1, u, v, u^2, u v, v^2) with
// u = (x - cx) / d, v = (y - cy) / d, d = half the image's diagonal in pixels and (cx, cy) the
// device's principal point: a quadratic holds the radial leading term of vignetting and a tilt.
// Scaled so that its mean over what the camera saw of the projector is 1. The default is flat.
struct LensFalloff {
    std::array<double, 6> c{1.0, 0.0, 0.0, 0.0, 0.0, 0.0};
    [[nodiscard]] bool flat() const { return c == LensFalloff{}.c; }
};

// A device: intrinsics (image positions, pixel centre +0.5), lens distortion (OpenCV's Brown-Conrady model
// about the principal point, bundle_adjust.h's device_image / device_ray; a projector's is fitted by the
// distortion trial, zero otherwise),
// pose in the screen frame (rotation device -> screen, position); projectors also carry their
// lens fall-off once the colour step has measured it (flat before, and always for cameras).
struct DeviceModel {
    std::string id;
    ImageSize resolution;
    double fx_px = 0.0;
    double fy_px = 0.0;
    double cx_px = 0.0;
    double cy_px = 0.0;
    std::array<double, 5> distortion{};
    Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
    Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
    LensFalloff falloff;
};

// LensFalloff's basis (1, u, v, u^2, u v, v^2) at image position (x, y) of `d`, and F(x, y) =
// its dot product with d.falloff.c (formula at LensFalloff).
[[nodiscard]] std::array<double, 6> falloff_basis(const DeviceModel& d, double x, double y);
[[nodiscard]] double falloff_at(const DeviceModel& d, double x, double y);

// The limits a fall-off must keep to be a lens's, F in [0.05, 5] over the image (its corners,
// edge middles and centre): the first image position (x, y) and F there that break them, or
// nullopt. The models file and the colour step refuse such a fall-off.
[[nodiscard]] std::optional<Eigen::Vector3d> falloff_out_of_range(const DeviceModel& d);

// What is known before calibrating: the screen's size, the camera's intrinsics and roughly its
// pose, each projector's resolution and data-sheet intrinsics (its pose is not used).
struct CalibrationPrior {
    ScreenModel screen;
    DeviceModel camera;
    std::vector<DeviceModel> projectors;
};

// A projector's lens measured on the bench (`mogao-calibrate procam`, docs/calibration.md "Projector intrinsics on
// the bench"; a site or rig file's projectors[k].procam): focal lengths and principal point in autocal's pixel
// convention (centres at +0.5) at the bench's resolution `size`, and OpenCV's distortion k1, k2, p1, p2, k3
// (dimensionless: the same at any resolution). `source` names the file, for errors and the report.
struct BenchLens {
    std::string source;
    ImageSize size;
    double fx_px = 0.0;
    double fy_px = 0.0;
    double cx_px = 0.0;
    double cy_px = 0.0;
    std::array<double, 5> distortion{};
};

// `prior` with projector k's data-sheet intrinsics replaced by lenses[k] where it is set, scaled to the prior's
// resolution when that is a uniform scale of the bench's (a projector run at half resolution): the projector fits
// start from it, its distortion held until the distortion trial frees it. Throws std::invalid_argument naming the
// source and both sizes when the aspects differ (by more than 0.1 %), or when `lenses` has more entries than the
// prior has projectors.
[[nodiscard]] CalibrationPrior with_bench_lenses(CalibrationPrior prior,
                                                 const std::vector<std::optional<BenchLens>>& lenses);

// What is known of the camera's intrinsics before calibrating (a chessboard calibration's
// uncertainty), as one standard deviation each: the weak prior that keeps the refinement of
// AutocalOptions::refine_camera_intrinsics well posed where the screen and the projectors say
// little (a Gaussian prior, i.e. MAP; Triggs et al. 2000, section 4.4). Positive.
struct CameraIntrinsicsSigma {
    double focal = 0.02;            // relative, of fx (fy follows with the prior's aspect ratio)
    double principal_point = 0.02;  // of the image's width, both axes
    double distortion = 0.05;       // k1 and k2
};

struct AutocalOptions {
    int warp_step_px = 2;             // warp/blend grid: one sample per this many output pixels, 1..64
    double blend_ramp = 0.12;         // blend ramp width, fraction of the projector's width, (0, 0.5]
    double min_contrast = 0.04;       // white - black for a camera pixel to count (shadow mask), (0, 1)
    double min_bit_fraction = 0.6;    // fraction of pixels a Gray bit must resolve to be used, (0, 1]
    int min_cells = 150;              // correspondences per projector, below: refused
    int max_correspondences = 20000;  // per projector (decoded camera pixels, evenly strided), >= min_cells
    int min_bits = 4;                 // resolved Gray bits per axis, below: decoding failed
    // Speed/accuracy knobs (docs/calibration.md, "Speed against accuracy"):
    int max_gray_bits = 0;       // Gray bits shown per axis, 0 = all (gray_code_bits of the extent); else
                                 // min_bits..16: the finest stripe is 2^(bits of the extent - max_gray_bits) px
    int frames_per_pattern = 1;  // camera frames averaged per pattern (noise / sqrt(frames)), 1..64
    // Phase shifting on top of the Gray code (phase_shift.h; docs/calibration.md): `phase_shifts` sinusoids per
    // axis (0 = off, else 3..16) of `phase_period_px` projector pixels ([4, 1024]; unwrapped where the Gray block
    // is at most half of it), pre-compensated for the projectors' assumed response `phase_gamma` ((0, 10]); a
    // refined position's sigma is at least `phase_sigma_floor_px` (camera footprint and model error, > 0).
    int phase_shifts = 8;  // 8, not 4: fewer harmonics of a wrong gamma and less noise (calibration-curves)
    double phase_period_px = 32.0;
    double phase_gamma = 2.2;
    double phase_sigma_floor_px = 0.29;
    // Shadow mask: a camera pixel counts only where white - black is also above this many sigmas of that
    // difference's noise (estimated from the black image), so that a noisy camera's dark pixels do not pass.
    double shadow_noise_sigmas = 5.0;  // >= 0
    // Shadow mask: and above this share of the projector's own contrast (the 99th percentile of white - black over
    // the pixels past min_contrast), [0, 0.5]. A screen that throws light back onto itself (a gain screen, a wide arc)
    // lights the screen past the projector's image by a few percent of its direct light; filmed bright enough, those
    // pixels pass an absolute threshold, carry no pattern, and the coarsest Gray bits stop resolving.
    double shadow_relative = 0.1;
    double max_edge_rms_m = 0.01;      // camera pose fit gate
    double max_projector_rms = 3.0;    // projector fit gate, rms in units of the decoding uncertainty, > 0
    double max_view_angle_deg = 75.0;  // camera rays steeper than this to the screen normal: grazing
    // Fit the cylinder's radius and arc in the bundle adjustment (bundle_adjust.h, refine_screen) when the prior's
    // are known only roughly; the heights stay as measured. The fitted screen is AutocalResult::screen.
    bool fit_screen = false;
    // On a told radius and arc (without fit_screen), fit the screen's top edge height (bundle_adjust.h,
    // refine_heights); the bottom edge stays as measured (the gauge). A tape leaves the heights millimetres off, and
    // a told span that is off pulls the camera and the projectors with it: content lands up to a pixel off with
    // nothing refused (docs/calibration.md, "Screen heights fitted"). The edge gate (max_edge_rms_m) then judges the
    // adjusted fit, not the pose's start on the told heights, and the edge points are assigned again through the
    // adjusted model, as with fit_screen. Off by default: with the span free, the camera's focal length is the only
    // tie between the screen's horizontal and vertical extents, so a wrong arc is taken up by the focal length and
    // the span together, consistently: the self-check cannot see it (roughscreen.toml, its arc 3 degrees off:
    // refused with told heights, calibrated 2 px off with fitted ones). For a site whose arc and radius are known
    // (drawings, a measured chord) and whose heights were taped.
    bool fit_heights = false;
    // On told heights (neither fit_screen nor fit_heights), check them against what the camera sees: the final
    // bundle adjustment is run once more with the top edge free (the bottom as told, the gauge), and the content
    // of both fits is compared in every projector's pixels (HeightsCheck). Refused when the mean shift is above
    // max_heights_shift_px: a tape error of a few millimetres in the span moves content by about as much as the
    // geometry goal allows (docs/calibration.md, "Screen heights checked"), and the self-check, posed on the same
    // told frame, cannot see it. The refusal names the heights and --fit-heights. Off: the heights are taken as told.
    bool check_heights = true;
    double max_heights_shift_px = 0.3;  // > 0, projector pixels (mean over each projector's content grid)
    // Try the screen's bow (ScreenModel::bow_m, 4 modes that vanish on its frame) in a second bundle adjustment,
    // from the first's result: for a screen that is not quite a cylinder (fabric bowed between its frame). The 3D
    // points then follow the bowed surface along the camera rays; its shape is seen through the camera-projector
    // baselines (stereo). Kept only where it pays: the projectors' mean fit rms (in units of the decoding's
    // uncertainty) must fall by more than bow_min_gain, else the cylinder stays (a free bow on a true cylinder
    // fits noise: 0.17 -> 0.21 px mean on the standard rig). Off: the screen is the cylinder.
    bool fit_bow = true;
    double bow_min_gain = 0.03;  // [0, 1)
    // Try the camera's focal length, principal point and radial distortion (k1, k2) free in the bundle adjustment
    // (bundle_adjust.h), from the projectors' correspondences and the screen's known shape, each pulled to the
    // prior's by `camera_sigma`: a second bundle adjustment from the first's result (the prior's intrinsics
    // taken as exact). Kept only where it pays: the fit's cost, in units of the first's (every projector's
    // correspondences and the edges, each at its own rms), must fall by more than intrinsics_min_gain, on about
    // the same correspondences. Where the prior's intrinsics are right, freeing them only lets them take up the
    // lit edges' and the decodings' small biases (0.171 -> 0.229 px mean on the standard rig at half scale,
    // 0.26 -> 1.9 px on the grazing camera), and the cost hardly falls (0.02 % and 0.1 % there); a focal length
    // 0.5 % off lowers it by 9 % (docs/calibration.md, "The camera's intrinsics, refined"). Off: the prior's
    // intrinsics are taken as exact.
    bool refine_camera_intrinsics = true;
    double intrinsics_min_gain = 0.01;  // [0, 1); 0 keeps the refined intrinsics whenever the cost falls
    // Try each projector's lens distortion (k1, k2, p1, p2 of OpenCV's model about its principal point; k3 stays
    // 0) free in a further bundle adjustment, after the bow's and the camera intrinsics' trials and with what they
    // kept free: a projection lens is not a pinhole, and a pinhole fitted to a distorting lens puts content off by
    // pixels at its image's edges. Kept per projector only where that projector's cost (its inlier
    // correspondences at the previous fit's rms) falls by more than distortion_min_gain, on about the same
    // correspondences, and the whole fit's cost (as the intrinsics' trial counts it) too; where only some
    // projectors keep it, the adjustment is run again with only theirs free. A pinhole lens lowers the cost by
    // about 0.1 % (fitting noise): nothing changes.
    // Off: the projectors are pinholes (docs/calibration.md, "Projector lens distortion").
    bool fit_projector_distortion = true;
    double distortion_min_gain = 0.01;  // [0, 1)
    CameraIntrinsicsSigma camera_sigma{};
    // Refused unless each refined intrinsic's standard deviation is at most this fraction of the prior's (the
    // screen and the projectors must determine it, not the prior), (0, 1]; and unless each lies within 4 of the
    // prior's sigmas of the prior's value.
    double camera_sigma_gate = 0.25;
    // Refused when the blend's predicted seam (predicted_seam_deviation: max |sum of the weights - 1| over the
    // overlaps, at every projector pixel) is above this, (0, 1]. A correct blend's figure is its ramps' pixel
    // quantisation, about 1.5 / ramp width in pixels (1.3 % at 960 px wide, 0.7 % at 1920: docs/calibration.md);
    // a weight that jumps shows as a line of the jump's height.
    double max_predicted_seam = 0.05;
    // Refused when the first camera frame after a pattern change holds more than this share of the previous
    // pattern's light (camera_timing.h, measured before any other pattern), [0, 1]. A share s mixes each phase
    // shift with the one before it: a constant offset of about s sin(2 pi / N) / (2 pi) of the period (N shifts;
    // 0.07 px at 2 %, 8 shifts of 32 px). From about 5 % the previous pattern's ghost passes the shadow mask and
    // the Gray code fails to decode, a refusal that would not name the cause.
    double max_frame_straddle = 0.02;
};

// Shows one signal image per projector (CV_32FC1 grey or CV_32FC3 RGB in [0, 1], projector
// resolution; empty = black) and returns the camera image (CV_32FC1, [0, 1]).
// The camera's exposure, gain and white balance must be locked (V4L2 exposure_auto = manual,
// libcamera AeEnable = false): images of different patterns are compared value by value.
class PatternSource {
public:
    virtual ~PatternSource() = default;
    [[nodiscard]] virtual cv::Mat1f show(const std::vector<cv::Mat>& signals) = 0;
    // False while the camera meters each image itself (auto-exposure): calibrate() and
    // calibrate_colour() refuse then, naming it.
    [[nodiscard]] virtual bool exposure_locked() const = 0;
    // Manual exposure relative to the one the source was set up with (1 = that one); the colour
    // step lengthens it for black levels and sets it back.
    virtual void set_relative_exposure(double factor) = 0;
    // True when the camera's frames come through a lossy codec (Motion-JPEG, as negotiated with the
    // device): the colour step then averages each image over several exposures
    // (ColourOptions::dither_frames). Known once a frame has been shown.
    [[nodiscard]] virtual bool lossy_frames() const { return false; }
};

// The mean of `frames` camera images of the same signals (frames >= 1): the camera's temporal
// noise falls as 1/sqrt(frames); each frame is one capture.
[[nodiscard]] cv::Mat1f show_averaged(PatternSource& source, const std::vector<cv::Mat>& signals, int frames);

// The screen's lit image for the edge fit (step 2), camera pixels in the camera's linear units: per
// pixel the largest over projectors k of (projector k white, the others black) minus `black` (every
// projector black). Not every projector white at once: where projectors overlap, their sum saturates a
// camera exposed for one of them, and a clipped edge of twice the height crosses its half level outward,
// 0.67 sigma of the camera's blur for a Gaussian one (millimetres on the virtual rigs). Where the camera clips
// a projector's white, its light there comes from the same projector at grey (camera_clipping.h). Shows each
// projector's white and grey `frames` times (2 n x frames captures, added to `captures`). Throws
// CalibrationRefused naming the camera's exposure where a white is clipped beyond kMaxWhiteOverdrive, or a grey
// clips too.
[[nodiscard]] cv::Mat1f lit_screen(PatternSource& source, const std::vector<ImageSize>& sizes, const cv::Mat1f& black,
                                   int frames, int& captures);

// Throws CalibrationRefused naming the camera's auto-exposure unless source.exposure_locked().
void require_locked_exposure(const PatternSource& source);

// The calibration cannot give a good result; the message says why (which projector, which gate,
// the measured value and its limit). The caller keeps its last good calibration.
class CalibrationRefused : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

struct ProjectorReport {
    std::string id;
    int column_bits = 0;
    int row_bits = 0;
    int cells = 0;           // correspondences used
    double rms_px = 0.0;     // projector fit residual, projector pixels
    double rms_sigma = 0.0;  // the same in units of the decoded positions' uncertainty (about 1: as good as
                             // the decoding; the gate max_projector_rms applies to it)
    double mean_view_angle_deg = 0.0;
    int lit_pixels = 0;        // camera pixels in its shadow mask
    int phase_refined = 0;     // of them, refined by the phase (the lesser of the two axes)
    double noise_sigma = 0.0;  // estimated noise of one black camera image (camera units)
};

// What the bow trial (AutocalOptions::fit_bow) found: the projectors' mean fit rms (units of the
// decoding's uncertainty) on the cylinder and with the bow, and whether the bow was kept.
// The camera intrinsics' trial (AutocalOptions::refine_camera_intrinsics): the fit's cost with the intrinsics
// free, in units of the cost with the prior's taken as exact (1 = no better), and whether they were kept.
struct IntrinsicsTrial {
    bool tried = false;
    bool kept = false;
    double relative_cost = 1.0;  // sum over blocks of points x (rms free / rms fixed)^2, over the points
};

// The projector distortion trial (AutocalOptions::fit_projector_distortion), per projector: its cost with the
// distortion free in units of its cost before (1 = no better), whether it was kept, and the fitted k1, k2, p1, p2
// (kept or not; the kept ones are in the projector's model).
struct DistortionTrial {
    bool tried = false;
    bool kept = false;
    double relative_cost = 1.0;
    double fit_relative_cost = 1.0;  // the whole fit's (every projector and the edges), the same for every projector
    std::array<double, 4> distortion{};
};

struct BowTrial {
    bool tried = false;
    bool kept = false;
    double cylinder_rms_sigma = 0.0;
    double bowed_rms_sigma = 0.0;
    std::array<double, 4> bow_m{};  // the fitted bow (kept or not)
};

// What the told heights' check (AutocalOptions::check_heights) found: the top edge the camera sees with the bottom
// as told, and how far content moves, in the showing projector's pixels, between the fit on the told span and the
// fit with the top edge free (a grid of 17 x 9 content points over the screen, each through both fits' models and
// screens: model_pixel; points a projector does not show are left out).
struct HeightsCheck {
    bool tried = false;
    double fitted_top_m = 0.0;
    double shift_mean_px = 0.0;
    double shift_max_px = 0.0;
};

// The blend's predicted seam and where it is (predicted_seam_deviation).
struct PredictedSeam {
    double deviation = 0.0;  // max |sum of the weights - 1|
    // Where it is: the projector whose output pixel (x, y) was walked there, and its screen point (theta in
    // radians, h in metres); projector -1 where no point is lit by two projectors.
    int projector = -1;
    int x = 0;
    int y = 0;
    double theta_rad = 0.0;
    double h_m = 0.0;
};

struct AutocalReport {
    int edge_points = 0;
    double edge_rms_m = 0.0;
    Eigen::Vector3d camera_position_m = Eigen::Vector3d::Zero();
    // The bundle adjustment's conditioning (BundleResult) with the camera's intrinsics free (the trial's, kept or
    // not): standard deviations of fx, cx, cy (px), k1, k2 (empty when not tried) and the scaled normal matrix's
    // condition number (of the fixed-intrinsics adjustment when not tried).
    std::vector<double> camera_intrinsics_sigma;
    double condition_number = 0.0;
    int captures = 0;
    double frame_straddle = 0.0;  // camera_timing.h: the previous pattern's share in a frame after a change
    std::vector<ProjectorReport> projectors;
    IntrinsicsTrial intrinsics;
    BowTrial bow;
    std::vector<DistortionTrial> distortion;  // per projector (empty when not tried)
    HeightsCheck heights;                     // AutocalOptions::check_heights (not tried on a fitted screen)
    PredictedSeam predicted_seam;  // predicted_seam_deviation of the result (the gate max_predicted_seam's figure)
};

struct AutocalResult {
    ScreenModel screen;  // the prior's, or the fitted one (AutocalOptions::fit_screen, fit_heights)
    ScreenCalibration calibration;
    DeviceModel camera;                   // fitted pose
    std::vector<DeviceModel> projectors;  // fitted models
    AutocalReport report;
};

// Gray code pattern: bit `bit` (0 = most significant of gray_code_bits(extent)) of the reflected
// binary code of the column (rows = false) or row index; 1 = white. Inverted flips it.
[[nodiscard]] int gray_code_bits(int extent);
[[nodiscard]] cv::Mat1f gray_code_pattern(ImageSize size, bool rows, int bit, bool inverted);

// Content frame size the calibration's warps address (the farm's frame), 1..16384 per side.
// Runs the whole method above. Throws CalibrationRefused (see the gates in AutocalOptions) or
// std::invalid_argument for a malformed prior/options.
[[nodiscard]] AutocalResult calibrate(PatternSource& source, const CalibrationPrior& prior, ImageSize content,
                                      const AutocalOptions& options = {});

// Steps 5 and 6 alone: the warp maps and blend masks (and the gamma 2.2 response) that fitted
// projector models give, exactly as calibrate() builds them (AutocalOptions::warp_step_px and
// blend_ramp are used). Lets a later step (appliance/selfcal) rebuild the calibration from
// re-estimated poses. Throws std::invalid_argument for an empty model list, a bad content size or
// options, and whatever validate_screen rejects.
[[nodiscard]] ScreenCalibration calibration_from_models(const std::vector<DeviceModel>& projectors,
                                                        const ScreenModel& screen, ImageSize content,
                                                        const AutocalOptions& options = {});

// The blend's own prediction of its seams, from the fitted models alone (no ground truth): max |sum of
// the blend weights - 1| over screen points two or more projectors light, content inset by 1 % of the
// frame on every side. Walked at every output pixel of every projector: the pixel's centre through its
// model onto the screen, then each other projector's pixel there (model_pixel, floor) and its blend weight
// (sample_blend); a weight that jumps shows as a line one pixel wide, which a coarser grid of screen points
// would miss. Includes the ramps' pixel quantisation (a pixel shows one weight over its extent). Throws
// std::invalid_argument when the models and the calibration's projectors differ in number.
[[nodiscard]] PredictedSeam predicted_seam_deviation(const std::vector<DeviceModel>& projectors,
                                                     const ScreenModel& screen, const ScreenCalibration& calibration);

// Screen point where a projector's image position (x, y) lands (through its distortion), as content (u, v)
// (unclamped), or nullopt-like NaN when the ray misses the cylinder.
[[nodiscard]] Eigen::Vector2d projector_content(const DeviceModel& projector, const ScreenModel& screen, double x,
                                                double y);

}  // namespace mogao::autocal
