// SPDX-License-Identifier: Apache-2.0
// Self-recalibration on the virtual rig (appliance/rig), measured against the rig's ground truth
// (autocal::measure_geometry), never against the monitor's own estimate: the wall's calibration is
// rendered through the TRUE (possibly bumped) projector poses and seen by the TRUE (possibly
// bumped) camera with the rig's noise, plus exposure changes and visitors occluding part of the
// view. The monitor starts from the rig's exact models (as if the full calibration had been
// perfect; its own residual, docs/calibration.md "Figures per rig", adds to the figures here), or
// from given models (SimulationOptions::start_model: a full calibration's estimate).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "appliance/autocal/colour_calibration.h"
#include "appliance/rig/virtual_rig.h"
#include "appliance/selfcal/self_calibrator.h"

namespace mogao::selfcal {

// A device's pose change at `at_s`: yaw/pitch/roll added (degrees, rig convention) and a shift
// (metres, screen frame). device: projector index, or -1 for the camera.
struct Bump {
    int device = 0;
    double yaw_deg = 0.0;
    double pitch_deg = 0.0;
    double roll_deg = 0.0;
    Eigen::Vector3d shift_m = Eigen::Vector3d::Zero();
    double at_s = 0.0;
};

// Parses "proj1:yaw=1deg,pitch=0.5deg,x=5mm" / "camera:roll=0.3deg" (keys yaw, pitch, roll in deg;
// x, y, z in mm or m). Throws std::invalid_argument naming the bad part.
[[nodiscard]] Bump parse_bump(const rig::VirtualRig& rig, const std::string& text);

enum class ContentKind { textured, plain, repetitive, dark };

struct SimulationOptions {
    double projector_scale = 0.5;  // autocal::scaled_rig
    double camera_scale = 0.5;
    double rate_hz = 2.0;  // monitored frames per simulated second
    int frames = 60;
    std::vector<Bump> bumps;
    ContentKind content = ContentKind::textured;
    bool moving_content = true;
    double exposure_jitter = 0.0;     // camera gain uniform in [1 - j, 1 + j] per frame
    double occlusion = 0.0;           // fraction of the camera view hidden by visitors, [0, 0.9]
    double occlusion_max = 0.0;       // > occlusion: each frame's fraction uniform in [occlusion, occlusion_max]
    double error_threshold_px = 1.0;  // "corrected" = mean geometric error below this
    // Ground truth measured every this many frames (and at the last and around corrections):
    // the long static run's cost is then the monitor's, not the ground truth's. >= 1.
    int truth_every = 1;
    std::uint64_t seed = 7;
    // The wall starts with the rig's true colour applied as a colour calibration would
    // (colour_of_rig, autocal::apply_measured_colour): per-channel LUTs, beta maps, scaled blends.
    bool measured_colour = false;
    // The monitor's starting models: none = the rig's exact models (models_of_rig, a perfect full
    // calibration); set = an estimate, e.g. autocal's on the same rig at the same scales read from
    // its models file, so that the full calibration's own residual is in every figure. Must have
    // the scaled rig's projectors (count, resolutions) and camera resolution; std::invalid_argument
    // otherwise.
    std::optional<SystemModel> start_model;
    SelfcalOptions selfcal;
};

struct SimulationFrame {
    double t_s = 0.0;
    SelfcalState state = SelfcalState::calibrated;
    bool waiting = false;
    double geometry_mean_px = 0.0;  // ground truth: the worst projector's mean error, its pixels (last measured)
    double cpu_ms = 0.0;
    std::string status;  // SelfcalStatus::text()
};

struct SimulationReport {
    std::optional<double> detected_after_s;   // first non-calibrated state after the first bump
    std::optional<double> corrected_after_s;  // first time after the bump: calibrated and error < threshold
    double start_error_px = 0.0;              // ground truth at the first frame (the starting models' residual)
    double error_before_px = 0.0;             // ground truth right after the bump (uncorrected), worst projector
    double final_error_px = 0.0;              // ground truth, last frame: the worst projector's mean
    double final_p95_px = 0.0;                // and its p95
    int corrections = 0;                      // times the state entered "correcting"
    int detections = 0;                       // times the state entered "drift detected"
    int waiting_frames = 0;
    double mean_cpu_ms = 0.0;  // per monitored frame (SelfCalibrator::step)
    SelfcalState final_state = SelfcalState::calibrated;
    std::vector<SimulationFrame> frames;
    std::vector<std::string> journal;
    ScreenCalibration initial_calibration;  // the wall at the start
    ScreenCalibration final_calibration;    // the wall after the last frame
    rig::VirtualRig final_rig;              // the true (scaled, bumped) rig at the end
};

// Runs the scenario. Throws std::invalid_argument for bad options.
[[nodiscard]] SimulationReport simulate(const rig::VirtualRig& rig, const SimulationOptions& options);

// The content frame at time t (linear grey, 960x540): textured = multi-scale blobs and strokes,
// repetitive = a regular grid of identical dots, plain = uniform grey, dark = the textured frame
// at 4 % of its light (a dim cave: its texture near the camera's noise, few features); moving
// content drifts.
[[nodiscard]] cv::Mat1f make_content(ContentKind kind, double t_s, bool moving, std::uint64_t seed);

// The rig's exact models (screen, camera, projectors) as the monitor's starting point.
[[nodiscard]] SystemModel models_of_rig(const rig::VirtualRig& rig);

// Projector k's input signal for a grey linear content frame, at the projector's resolution:
// warp -> content -> x blend (+ beta) -> the calibration's response (render_output's formula,
// appliance/warp/composite.h). CV_32FC1 (exactly x^(1/2.2)) for calibration_from_models' plain
// gamma 2.2 LUT without beta; CV_32FC3 (per-channel LUT and beta) for a calibration with colour.
[[nodiscard]] cv::Mat projector_signal(const ProjectorCalibration& pc, const cv::Mat1f& content);

// The rig's true photometry as a colour calibration would measure it (autocal::MeasuredColour;
// colour_calibration.h step 3-4 with the rig's exact light model, virtual_rig.h): amplitude
// A_kc = brightness_kc (1 - black_k), response R_kc(s) = s^gamma_kc, black_kc = brightness_kc
// black_k, matched white W_c = min_k A_kc; LUT_kc(x) = (x W_c / A_kc)^(1 / gamma_kc) with `entries`
// samples, black in W units. The colour counterpart of models_of_rig.
[[nodiscard]] autocal::MeasuredColour colour_of_rig(const rig::VirtualRig& rig, int entries = 4096);

}  // namespace mogao::selfcal
