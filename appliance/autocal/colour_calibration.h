// SPDX-License-Identifier: Apache-2.0
// Photometric calibration after the geometric one (seed paper II.B "colour calibration
// from channel response functions"): each projector's per-channel response measured from camera
// images of grey ramps with the camera's exposure locked, inverse LUTs, luminance and white point
// matched across projectors, and black-level compensation (beta maps) so that the overlaps and the
// rest of the screen show the same black. docs/calibration.md, "Colour and black level".
//
// Camera: monochrome with a flat spectral response (the virtual rig's; a colour camera's channels
// summed the same way): one channel of one projector is shown at a time, so the camera measures
// that channel's light. Camera units are its image values at the base (locked) exposure.
//
// Method (Majumder & Stevens, "Color nonuniformity in projection-based displays: analysis and
// solutions", IEEE TVCG 10(2) 2004: the display's range at a point is [black, white]; make it the
// same everywhere by per-pixel attenuation of the white and offset of the black. Here in a
// documented simpler form: one gain per projector and channel (its chrominance, assumed the same
// over its image), times a per-pixel luminance attenuation from the projector's lens fall-off,
// measured as a smooth quadratic (autocal.h's LensFalloff), towards a flat white: the limit of
// Majumder & Stevens' perceptual smoothing, "Perceptual photometric seamlessness in projection-based
// tiled displays", ACM TOG 24(1) 2005, at zero allowed gradient, which gives up the brightness of
// the dimmest corner that shows content):
//  1. Response: projector k, channel c at levels s_i = i / (ramp_steps - 1), the others black;
//     y_kc(s) = mean over the camera pixels k lights (its coverage mask, eroded) of the image
//     minus the all-black image; levels up to 1/4, and 1/32 and 1/16, again at low_end_exposure x
//     the locked exposure (they are a few camera codes at the base exposure, and the black-level
//     offsets live there), unless the camera saturates. A_kc = y_kc(1) is the full-white amplitude; the
//     normalised response R_kc(s) = y_kc(s) / A_kc (made non-decreasing) is interpolated as a
//     power law between measured levels (linear in log s - log R, so a pure gamma is exact) and
//     continued below s_1 with the first segment's exponent.
//  0. Screen bounce (`screen_bounce`, with `lens_falloff`): a concave screen lights itself, so each projector's
//     full-level images hold, besides its direct light, the light its own light throws across the screen (seen
//     also where it does not reach: its only light there). Modelled as one bounce between patches of the fitted
//     screen (screen_bounce.h) from the light each image shows on them, its reflectance rho fitted by least
//     squares to the pixels no projector's direct light reaches in each image, and rho times the bounce taken
//     out of every image before steps 1a and 1b: each projector's fall-off and amplitudes are then its direct
//     light's. Left in, a projector's own bounce is flattened with its light while the others' is not, which
//     differs on the two sides of a seam.
//  1a. Camera vignetting (`camera_vignetting`, with `lens_falloff`): V(rho) fitted jointly with a radial
//     fall-off per projector to every projector's summed full-level image (camera_vignetting.h, model and
//     why); the images of steps 1b and 2 are divided by V, so that they are the screen's light.
//  1b. Fall-off (`lens_falloff`): F_k = the quadratic in projector k's image positions fitted by
//     least squares to its summed full-level images over the eroded mask, each camera pixel placed
//     in the projector by the camera and projector models through the screen; scaled to mean 1
//     there, and A_kc taken as the mean over the same pixels, so A_kc F_k(p) is the light of pixel p.
//  2. Black: `dark_frames` all-black images at `dark_exposure` x the base exposure (black levels are
//     ~0.2 % of white, below one 8-bit code at the base exposure; less where the brightest black would pass
//     0.9 of full scale at it, down to `low_end_exposure`: a camera exposed brightly), averaged; least squares over
//     the camera pixels inside the screen: L0(p) = a + sum_k beta_k M_k(p) with M_k the coverage
//     masks times F_k (a = ambient, beta_k = projector k's black). Needs at least one overlap to separate
//     a from the betas. Black's chromaticity is taken to be the projector's white's (light leaking
//     through the same filters): black_kc = beta_k A_kc / sum_c A_kc (the mono camera sees the
//     mean of the channels, and A_kc is one channel's light as it sees it).
//  3. Matching: matched white W_c = min_k A_kc per channel (the largest white every projector can
//     show, so the white point is the same everywhere; it is the per-channel minimum, not a chosen
//     standard white). Black floor: T_c = max over screen points of B_c(p) = sum_{k lighting p}
//     black_kc F_k; deficit D_c(p) = T_c - B_c(p) >= 0. White floor S = min F_k(p) over the
//     pixels that show content (1 without fall-off).
//  Gain screen (ScreenModel::gain != 1, its data sheet told): in steps 1a, 1b and 2 each camera pixel's view of
//     projector k is divided by the screen's gain toward the camera there (through the fitted models), so F_k, A_kc
//     and the blacks are a matte screen's; in steps 3 and 4 every F_k(p) is the lens's times the gain toward
//     ScreenModel::viewer_m at the screen point p shows: the compensation holds where the visitors stand. The
//     lobe's half-gain angle is measured rather than taken from the data sheet (estimate_half_gain_angle): the
//     angle whose gain toward the camera, divided out, leaves the least residual in step 1a's fit; the peak gain
//     cancels (it scales every projector alike) and stays the data sheet's.
//  Exposure dither (a camera whose frames come through Motion-JPEG, PatternSource::lossy_frames): the codec
//     rounds each 8 x 8 block's mean to its quantisation step and drops the noise that would dither it, so a flat
//     image's wide areas share one rounding, the same in every frame at one exposure (0.7 % of white at quality 72,
//     more at the ramp's low end and in black). Every image above is then the mean of `dither_frames` images
//     (`full_level_frames` at the full level) at exposures spread over [1, 1 + dither_span] x its own, each
//     divided by its exposure: the camera is linear in exposure, and each exposure moves every block's light by a
//     different fraction of its step. The span is cut where the brightest pixels would saturate. The screen
//     bounce's reflectance (step 0) is fitted on one white image per projector at low_end_exposure, where the
//     bounce is a few codes at the base exposure.
//  4. Per projector: LUT_kc(x) = R_kc^-1(x W_c / A_kc) (the ResponseCurve, x in matched-white
//     units); beta_kc(p) = alpha_k(p) D_c(p) / (W_c F_k(p)) (the BlackOffset, one sample per output pixel, split
//     between the projectors lighting p by their blend weights); alpha_k replaced by alpha_k s S / F_k with
//     s = 1 - max_c,p D_c(p) / (W_c S) so that x = alpha s S c / F + beta stays <= 1. The screen then shows
//     T_c + s S W_c c everywhere for content c.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "appliance/autocal/autocal.h"
#include "appliance/autocal/camera_vignetting.h"

namespace mogao::autocal {

struct ColourOptions {
    int ramp_steps = 9;             // levels per channel including 0 and 1, 3..64
    int dark_frames = 8;            // averaged black images, 1..64
    double dark_exposure = 40.0;    // exposure multiplier for the black images (at most), [1, 1000]
    double low_end_exposure = 8.0;  // exposure multiplier for the ramp's low end (levels <= 1/4), [1, 1000]
    // Exposure dither (see "Method"; lossy frames only): every image of a ramp level or of black is the mean of
    // `dither_frames` images at exposures spread over [1, 1 + dither_span] x its own, 1..64; the full level's of
    // `full_level_frames`, 1..64 (steps 1a and 1b fit its shape). dither_span in [0, 0.5]; 1 frame: none.
    int dither_frames = 4;
    int full_level_frames = 8;
    double dither_span = 0.5;
    int lut_entries = 4096;       // ResponseCurve samples, 2..kMaxResponseEntries (fine: x^(1/gamma) is steep near 0)
    double min_amplitude = 0.05;  // a channel's full white must reach this much of full scale
    double max_fit_rms = 0.03;    // rms of the measured response around a pure gamma, gate
    int mask_erode_px = 2;        // coverage masks shrunk by this many camera pixels (blur, seams)
    bool lens_falloff = true;     // step 1b: measure each projector's fall-off and attenuate per pixel
    int falloff_min_samples = 1000;       // camera pixels a projector's fall-off fit needs, >= 6
    bool camera_vignetting = true;        // step 1a: measure the camera's vignetting (with lens_falloff only)
    double vignetting_prior_sigma = 0.2;  // its prior on a and b (camera_vignetting.h), > 0
    int vignetting_step_px = 2;           // every this many camera pixels (x and y) a sample of it, 1..16
    // A gain screen's half-gain angle estimated from the camera's images (step 1a), not taken from its
    // data sheet (with camera_vignetting and lens_falloff; a matte screen has none).
    bool estimate_half_gain_angle = true;
    // Step 0: the light a concave screen throws onto itself, measured and taken out of each projector's images
    // (with lens_falloff).
    bool screen_bounce = true;
};

struct ChannelResponse {
    std::vector<double> levels;    // s_i
    std::vector<double> measured;  // R(s_i), normalised, non-decreasing, 0 at s = 0, 1 at s = 1
    double amplitude = 0.0;        // A_kc, camera units
    double gamma = 0.0;            // least-squares pure gamma of R (reported, not used)
    double gamma_rms = 0.0;        // rms of R - s^gamma
};

struct ProjectorPhotometry {
    std::string id;
    std::array<ChannelResponse, 3> channels;
    double black = 0.0;            // beta_k, camera units (mono)
    std::array<double, 3> gain{};  // W_c / A_kc
    LensFalloff falloff;           // F_k (flat unless ColourOptions::lens_falloff)
};

struct ColourResult {
    std::vector<ProjectorPhotometry> projectors;
    std::array<double, 3> matched_white{};  // W_c, camera units
    std::array<double, 3> black_floor{};    // T_c, camera units
    double ambient = 0.0;                   // a, camera units (mono)
    double alpha_scale = 1.0;               // s
    double white_floor = 1.0;               // S: the wall's white is S W_c
    CameraVignetting vignetting;            // step 1a's (measured = false when not)
    // The gain screen's half-gain angle the step used, degrees: estimated (step 1a) or the data sheet's; with
    // step 1a's residual rms (relative) at the data sheet's angle and at the estimate.
    double half_gain_angle_deg = 0.0;
    bool half_gain_angle_estimated = false;
    double told_half_gain_rms = 0.0;
    double half_gain_rms = 0.0;
    // Step 0: the screen's reflectance for its own light (rho, screen_bounce.h) fitted where no projector lights
    // it directly, and how many camera pixels that fit had; 0 when not measured.
    double screen_bounce_reflectance = 0.0;
    int screen_bounce_samples = 0;
    int captures = 0;
};

// Measures (steps 1-2) and applies (steps 3-4) to `calibration` (from calibrate(): its warps,
// blends, the fitted `camera` and `projectors` give each output pixel's screen point, which
// projectors light it and which projector pixel each camera pixel sees). Sets each projector
// model's `falloff` to the measured one (what the models file keeps for self-recalibration).
// The screen's half-gain angle the step used is in ColourResult (the caller keeps it in its screen model).
// Throws CalibrationRefused when the camera's exposure is not locked, a channel is too dark for
// the camera, a response is not monotone or far from any gamma (max_fit_rms), a fall-off cannot
// be measured (too few pixels seen) or is no lens's (outside [0.05, 5] of its mean), or the black
// levels cannot be separated (no overlap seen); std::invalid_argument for bad options or a camera
// model whose resolution is not its images'.
[[nodiscard]] ColourResult calibrate_colour(PatternSource& source, const ScreenModel& screen, const DeviceModel& camera,
                                            std::vector<DeviceModel>& projectors, ScreenCalibration& calibration,
                                            const ColourOptions& options = {});

// What the colour step measured of the screen, into the screen's model (what the models file keeps): the half-gain
// angle it used and the screen's reflectance for its own light (clamped to [0, 0.99], the models file's range).
void keep_screen_measurements(const ColourResult& colour, ScreenModel& screen);

// The colour a calibration measured, in the part that does not depend on where the projectors
// point: what a bumped projector keeps (self-recalibration, appliance/selfcal, re-applies it to the
// corrected geometry). A projector's response and its black light are properties of its lamp,
// panel and filters, not of its pose, and so is its lens fall-off (kept in its DeviceModel, in its
// own image positions); the black floor T_c, the white floor S, the beta maps and the blend scale s
// are defined on the screen's overlaps and so follow the geometry (step 3-4 redone for it).
struct MeasuredColour {
    std::vector<ResponseCurve> responses;      // per projector: LUT_kc of step 4 (input in matched-white units)
    std::vector<std::array<double, 3>> black;  // per projector and channel: black_kc / W_c (matched-white units, >= 0)
};

// Steps 3 (black floor) and 4 (maps) for the geometry of `models`: every projector's response
// becomes colour.responses[k], its beta (one sample per output pixel, as calibrate_colour) the
// compensation of the blacks at the overlaps `models` give (through each model's fall-off), and
// the blend masks become w s S / F (s = 1 - max D / (W S); S and F as in step 4, 1 for flat
// models). `calibration` must be the unscaled one calibration_from_models(models) builds (no
// beta). All-zero blacks: no beta map (empty) and s = 1, only the responses change. Returns s.
// Throws std::invalid_argument when the sizes do not match (projector count, response validity).
double apply_measured_colour(const MeasuredColour& colour, const std::vector<DeviceModel>& models,
                             const ScreenModel& screen, ScreenCalibration& calibration);

// The inverse, for a calibration that calibrate_colour or apply_measured_colour made with `models`
// (e.g. read back from its MPCDI file; the fall-offs from its models file): responses copied;
// s = the largest w F / S (alpha = 1 wherever one projector alone lights the screen); the blacks by
// linear least squares on
//   beta_kc(p) = (w_k(p) / (s S)) (t_c - sum over projectors j lighting p of b_jc F_j(p))
// over every other output pixel (x and y) with w_k > 0, for the unknowns t_c (the black floor)
// and b_jc. A calibration without beta maps (or all-zero ones) gives zero blacks. Throws
// std::invalid_argument naming the cause when the models do not match the calibration, or when it
// has beta maps that this does not explain: the blacks not separable (no overlap), or an rms
// residual above 10 % of the maps' rms (maps made some other way; re-deriving them is not possible).
[[nodiscard]] MeasuredColour measured_colour(const ScreenCalibration& calibration,
                                             const std::vector<DeviceModel>& models, const ScreenModel& screen);

// Step 1's interpolation: normalised light R(s) of a measured channel, s in [0, 1].
[[nodiscard]] double response_at(const ChannelResponse& r, double s);

// Image position of screen point (theta, h) in a fitted model (through its lens distortion), or NaN when it is behind
// the projector or outside its image.
[[nodiscard]] Eigen::Vector2d model_pixel(const DeviceModel& d, const ScreenModel& s, double theta, double h);

}  // namespace mogao::autocal
