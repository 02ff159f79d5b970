// SPDX-License-Identifier: Apache-2.0
// Continuous self-recalibration (docs/calibration.md, "Self-recalibration"): the
// kiosk-facing object. Each monitored frame, step(content, camera_frame, t) measures (monitor.h),
// filters each projector's and the camera's pose change (pose_kalman.h) and decides:
//   calibrated -> drift detected: a projector's filtered drift is above `drift_threshold_px`
//     (mean displacement of its image on the screen, in its own pixels) and significant (outside
//     the filter's own uncertainty, x^T P^-1 x > gate); it stays detected until under half the threshold;
//   drift detected -> correcting: that lasted `hold_s` seconds; the corrected warp maps and blend
//     masks (autocal::calibration_from_models on the re-estimated poses, intrinsics fixed) with the
//     calibration's measured colour re-applied (below) are blended in linearly over `transition_s`
//     (warps, blends and beta maps); step() returns each intermediate calibration;
//   correcting -> calibrated: the corrected calibration becomes the reference, is saved
//     (calibration_store.h) when `store` is set, and the filters restart from zero;
//   drift detected -> cannot correct: the re-estimated pose puts less than
//     (1 - max_offscreen_loss) of the projector's on-screen image of its reference on the screen;
//     nothing is changed, the state stays until the drift is gone (the projector put back) or a
//     full calibration replaces the reference. Also when a projector is lost: for hold_s its
//     matches fall under a fifth of its typical count while every other projector keeps at least
//     half of its own (the content is not to blame: its image moved beyond what the monitor can
//     follow, e.g. mostly off the screen).
// The camera fit is checked against the screen's edges in the frame (Monitor::edges_moved): the
// screen does not move, so a fit that moves the camera while the edges stay where they were is
// projectors moving together (two of three by the same yaw make such a consensus) and gives no
// camera measurement; the projectors are then fitted against the reference camera.
// A frame with fewer than `min_matches` matches for a projector gives that projector no
// measurement (its filter only predicts): waiting, "insufficient evidence". A camera whose filtered
// pose change is significant and moves the screen's image by more than `camera_rebase_px` for hold_s re-bases the
// monitor's camera (the projectors' estimates are made against the per-frame camera fit already). Every decision is a
// journal line with before/after figures.
//
// Colour through a correction (docs/calibration.md, "Self-recalibration", "Colour"): the
// calibration's measured colour (autocal::calibrate_colour: per-projector per-channel response
// LUTs, black-level beta maps, blend masks scaled by s) is recovered once, at construction, as
// autocal::measured_colour of `calibration` and the model: each projector's response and its
// black light per channel. Those are the projector's own (lamp, panel, filters) and survive a bump;
// the beta maps, the black floor and s are defined on the screen's overlaps (Majumder & Stevens,
// IEEE TVCG 10(2) 2004: compensate each point's black up to the brightest black anywhere), so each
// correction re-derives them for the corrected geometry (autocal::apply_measured_colour, the same
// code calibrate_colour ends with), never copies them pixel for pixel. A calibration whose beta maps
// this cannot explain (made some other way) keeps them unchanged through corrections, with a
// journal line at the first step saying so.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "appliance/autocal/autocal.h"
#include "appliance/autocal/colour_calibration.h"
#include "appliance/selfcal/fallback_pattern.h"
#include "appliance/selfcal/monitor.h"
#include "appliance/selfcal/pose_kalman.h"
#include "appliance/selfcal/selfcal_status.h"
#include "common/projector_calibration.h"

namespace mogao::selfcal {

struct SelfcalOptions {
    double drift_threshold_px = 0.5;  // > 0
    double hold_s = 2.0;              // >= 0
    double transition_s = 3.0;        // >= 0
    int min_matches = 30;             // per projector, >= 6
    double max_offscreen_loss = 0.5;  // (0, 1]
    // The camera is re-based when its filtered pose change moves the screen's image by more than
    // this many camera pixels on average (a small shift with the rotation that compensates it
    // hardly moves the image: a threshold in degrees or mm re-based on such noise). >= 0.
    double camera_rebase_px = 0.5;
    std::filesystem::path store;         // empty: corrected calibrations are not written
    std::filesystem::path models_store;  // empty: not written; else the corrected models (save_models) too
    MonitorOptions monitor;
    KalmanOptions kalman;
    KalmanOptions camera_kalman;
    autocal::AutocalOptions build;  // warp_step_px, blend_ramp of the rebuilt calibration
    PatternOptions pattern;         // the content-independent fallback; off by default
};

struct StepResult {
    SelfcalStatus status;
    std::optional<ScreenCalibration> calibration;  // set when the wall must change this frame
    std::vector<std::string> journal;              // lines for the journal (decisions, corrections)
    double cpu_ms = 0.0;                           // this call's CPU time (thread)
};

class SelfCalibrator {
public:
    // `model`: the calibrated system (e.g. autocal's AutocalResult camera and projectors);
    // `calibration`: what the wall shows now (built from `model`). Throws std::invalid_argument for
    // bad options or mismatched projectors.
    SelfCalibrator(const SystemModel& model, const ScreenCalibration& calibration, const SelfcalOptions& options = {});

    // One monitored frame: the content being projected (CV_32FC1 linear grey, any size), the
    // camera frame of the screen (CV_32FC1 linear [0, 1], camera resolution) and its time in
    // seconds (non-decreasing). Throws std::invalid_argument for bad sizes or time going back.
    [[nodiscard]] StepResult step(const cv::Mat1f& content, const cv::Mat1f& camera_frame, double t_s);

    // Content-independent fallback (fallback_pattern.h; only with options.pattern.enabled).
    // After a step() that waited for evidence, the monitor asks for a complementary pattern pair
    // for options.pattern.recheck_s seconds: the display adds pattern_for_refresh(k, its content
    // size) to the linear content at two consecutive refreshes k = 0, 1 (+a P, then -a P; CV_32FC1,
    // signed, the content's size) and passes the camera frames of the two to step_pattern.
    // nullopt: no pattern wanted (fallback off, or the content gives enough evidence).
    [[nodiscard]] std::optional<cv::Mat1f> pattern_for_refresh(std::int64_t k, cv::Size content_size) const;

    // One monitored frame from a pattern pair: the content (any size; only its size is used),
    // the camera frames of the refresh with +a P and of the one with -a P (same exposure, camera
    // resolution). The monitor works on their difference, 2a P as the screen shows it, under the
    // same evidence rules as step() (min_matches per projector, the filters' gates, hold_s): it
    // never corrects from too little evidence. Throws std::invalid_argument when the fallback is
    // off, for frames of different or wrong sizes or time going back.
    [[nodiscard]] StepResult step_pattern(const cv::Mat1f& content, const cv::Mat1f& camera_plus,
                                          const cv::Mat1f& camera_minus, double t_s);

    [[nodiscard]] const ScreenCalibration& calibration() const { return wall_; }  // on the wall now
    [[nodiscard]] const SystemModel& model() const { return monitor_.model(); }
    [[nodiscard]] SelfcalState state() const { return state_; }

private:
    StepResult run_step(const cv::Mat1f& content, const cv::Mat1f& camera_frame, double t_s, bool pattern_pair = false);
    void filter(const FrameMeasurement& m, double dt, StepResult& r);
    void decide(double t_s, StepResult& r);
    void start_correction(double t_s, const std::vector<int>& drifting, StepResult& r);
    void advance_correction(double t_s, StepResult& r);
    void rebase_camera(double t_s, StepResult& r);
    [[nodiscard]] ScreenCalibration corrected_calibration(const std::vector<autocal::DeviceModel>& models,
                                                          StepResult& r) const;
    bool check_lost(double t_s, StepResult& r);
    [[nodiscard]] double device_drift_px(const autocal::DeviceModel& d, const Pose6& delta) const;
    [[nodiscard]] double drift_px(int k, const Pose6& delta) const;
    [[nodiscard]] double camera_drift_px(const Pose6& delta) const;  // mean image displacement, camera pixels
    [[nodiscard]] double on_screen_fraction(const autocal::DeviceModel& d) const;

    SelfcalOptions options_;
    Monitor monitor_;
    ScreenCalibration wall_;
    ScreenCalibration before_;
    ScreenCalibration after_;
    std::vector<autocal::DeviceModel> after_models_;
    autocal::MeasuredColour colour_;      // the calibration's measured colour (see the header comment)
    std::vector<BlackOffset> kept_beta_;  // beta maps measured_colour could not explain, kept as they are
    bool edges_disagree_ = false;         // the last frame's camera fit was rejected by the screen's edges
    std::string pending_journal_;         // said at the next step
    std::vector<PoseKalman> filters_;
    PoseKalman camera_filter_;
    SelfcalState state_ = SelfcalState::calibrated;
    double last_t_ = 0.0;
    bool started_ = false;
    double drift_since_ = 0.0;
    double camera_since_ = -1.0;
    double correction_start_ = 0.0;
    std::string reason_;
    bool report_after_ = false;
    std::vector<double> typical_matches_;  // per projector: running mean of its matches when measured
    std::vector<char> contested_;          // per projector: its last measurement, rejected, said "no change"
    std::vector<int> seen_above_;          // per projector: measured frames in a row with a fresh drift
    std::vector<char> stepped_;            // per projector: its last measurement made a step (PoseKalman)
    std::vector<double> lost_since_;       // per projector: since when it is lost, -1 if not
    bool pattern_mode_ = false;            // the pattern pair is wanted
    double pattern_since_ = 0.0;
    mutable cv::Mat1f pattern_;  // the unit pattern P at the last content size (a cache)
};

// Linear blend of two calibrations of the same layout: warps (where both finite; otherwise the
// nearer end's), blend masks and beta maps (where both have one of the same size; otherwise the
// nearer end's); the responses are b's. s in [0, 1]. Throws std::invalid_argument when layouts differ.
[[nodiscard]] ScreenCalibration interpolate_calibration(const ScreenCalibration& a, const ScreenCalibration& b,
                                                        double s);

}  // namespace mogao::selfcal
