// SPDX-License-Identifier: Apache-2.0
// The on-site self-check of a calibration, with no ground truth: marks at known content positions are
// shown through the new warp and blend, filmed by the calibration camera, and each mark's position on
// the screen is compared with where its content belongs, in the showing projector's pixels
// (docs/calibration.md, "The self-check").
//
// Method. Marks: a grid of `columns` x `rows` content points (u, v) inset by `inset` of the frame on every
// side; each a round Gaussian spot of standard deviation `mark_sigma` x the screen's height on the screen
// (content is addressed in screen units, so a spot is round on the screen whatever the projector's
// keystone). Projector k shows, alone, every mark whose centre it shows (blend weight > 0 there, at least
// 3 sigma inside its image): its signal at output pixel (x, y) is the spot's value at the content the
// warp puts there (sample_warp), and 0 where its blend is 0; one capture per projector, minus a black one,
// the mean of `frames` frames each. Each mark's camera position is the intensity-weighted centroid of
// the lit pixels (above a fifth of the window's peak) in a window of 3 spot sigmas around the predicted
// position, re-centred three times (thresholded centroid of a target image: Shortis, Clarke & Short 1994,
// "A comparison of some techniques for the subpixel location of discrete target images", SPIE 2350).
//
// Where a mark belongs. A calibration agrees with its own camera by construction: the projector models
// are fitted to what the camera saw through that camera's model, so a mark lands, in the camera image,
// where the calibration's camera predicts it, however wrong that camera's intrinsics are (the content is
// then off on the screen, and the camera cannot tell from the marks alone). What the camera sees that
// the calibration does not decide is the screen's frame: its top and bottom edges at their measured
// heights and its ends (the screen's known boundary fixes the camera: Sajadi & Majumder 2009, IEEE TVCG
// 15(6)). The check therefore poses its own camera on the frame alone (a white and a black capture; the
// screen's lit edges as in step 2 of autocal.h, then Gauss-Newton on the 6 pose parameters with each edge
// point's distance from its edge in camera pixels; the calibration's intrinsics, which the frame alone does
// not determine well), takes each mark's observed camera position through that camera onto the screen (the
// calibration's screen model), and compares it with the screen point its content belongs at: the distance
// in the showing projector's pixels through its fitted model. Marks that camera sees more steeply than
// `max_view_angle_deg` are left out. Which errors this sees and which it cannot: docs/calibration.md,
// "The self-check".
#pragma once

#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "appliance/autocal/autocal.h"

namespace mogao::autocal {

struct SelfCheckOptions {
    int columns = 16;          // marks across the content, >= 2
    int rows = 6;              // marks down the content, >= 2
    double inset = 0.07;       // of the frame on every side, (0, 0.5)
    double mark_sigma = 0.03;  // spot standard deviation, fraction of the screen's height, (0, 0.1]
    int frames = 2;            // camera frames averaged per capture, 1..64
    // Marks the check's camera sees more steeply than this to the screen's normal are not measured: there a small
    // error of its pose moves the back-projected point by 1 / cos of the angle.
    double max_view_angle_deg = 60.0;  // (0, 90)
    int min_marks = 8;                 // marks found, below: the check fails (refused)
    // The gate (max_self_check_px, --max-self-check-px): a calibration whose marks land further than this from
    // where they belong (mean, the showing projector's pixels) is refused, > 0. Above the check's own figure on
    // every rig that calibrates (at most about 0.45 px: its floor is 0.1-0.2 px above the truth) and below what
    // it reads for a wrong camera's 1 px (it reads about two thirds of that): docs/calibration.md.
    double max_mean_px = 0.65;
};

struct SelfCheckMark {
    int projector = 0;
    Eigen::Vector2d content = Eigen::Vector2d::Zero();          // (u, v)
    Eigen::Vector2d camera_expected = Eigen::Vector2d::Zero();  // the check's camera, image position
    Eigen::Vector2d camera_observed = Eigen::Vector2d::Zero();  // the spot's centroid (NaN: not found)
    double error_px = 0.0;        // the showing projector's pixels between where it landed and where it belongs
    double error_mm = 0.0;        // the same on the screen
    double view_angle_deg = 0.0;  // the check camera's ray to the screen's normal there
};

struct SelfCheckResult {
    std::vector<SelfCheckMark> marks;  // found marks
    int shown = 0;                     // marks shown (found or not)
    int steep = 0;                     // of them, seen too steeply to be measured (max_view_angle_deg)
    int captures = 0;
    double mean_px = 0.0;
    double p95_px = 0.0;
    double max_px = 0.0;
    double mean_mm = 0.0;
    double own_camera_mean_px = 0.0;  // the same marks through the calibration's own camera (blind to it)
    DeviceModel camera;               // the check's camera: the calibration's intrinsics, posed by the frame
    int edge_points = 0;
    double edge_rms_px = 0.0;  // the frame fit's rms, camera pixels
    cv::Mat1f filmed;          // every projector's marks as the camera saw them (minus black, summed), for the eye
};

// Projector k's verification signal (CV_32FC1, its output size): the marks through its warp and blend.
[[nodiscard]] cv::Mat1f verification_signal(const AutocalResult& calibrated, int k, const SelfCheckOptions& options);

// Throws CalibrationRefused naming the figure, its gate (max_self_check_px) and the likely causes when
// check.mean_px > o.max_mean_px.
void check_self_check_gate(const SelfCheckResult& check, const SelfCheckOptions& o);

// report.json's "self_check" block: the figures, the gate and how many marks and captures.
[[nodiscard]] nlohmann::json self_check_report(const SelfCheckResult& check, const SelfCheckOptions& o);

// report.json's "screen.heights_check", the other check that needs no ground truth (autocal.h,
// AutocalOptions::check_heights): whether it ran, the top edge the camera sees (metres), how far content
// moves between the told and the seen top edge in projector pixels (mean, max) and the gate it was held to.
[[nodiscard]] nlohmann::json heights_check_report(const HeightsCheck& h, double gate_px);

// Runs the check on `source` (the projectors showing `calibrated` and the camera it was made with).
// `prior`: what the calibration was told (the check's camera starts from its intrinsics). Throws
// std::invalid_argument for bad options and CalibrationRefused when fewer than min_marks marks are found or
// the frame cannot be fitted.
[[nodiscard]] SelfCheckResult run_self_check(PatternSource& source, const CalibrationPrior& prior,
                                             const AutocalResult& calibrated, const SelfCheckOptions& options = {});

}  // namespace mogao::autocal
