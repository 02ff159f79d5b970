// SPDX-License-Identifier: Apache-2.0
// `mogao-calibrate-sim selfcal-simulate` (selfcal_command.h).
#include "kiosk/calibrate/selfcal_command.h"

#include <cstdio>
#include <exception>
#include <stdexcept>

#include "appliance/autocal/model_store.h"
#include "appliance/rig/rig_file.h"

namespace mogao::calibrate {
namespace {

using selfcal::ContentKind;

int run_simulate(const std::string& rig_path, const std::string& models_path,
                 const std::vector<std::string>& bump_texts, double bump_at, selfcal::SimulationOptions o,
                 bool verbose) {
    const rig::VirtualRig rig = rig::load_rig(rig_path);
    for (const std::string& b : bump_texts) {
        selfcal::Bump bump = selfcal::parse_bump(rig, b);
        bump.at_s = bump_at;
        o.bumps.push_back(bump);
    }
    if (!models_path.empty()) {
        // autocal's estimate (mogao-calibrate-sim rig --rig ... --scale S: calibration.models.json).
        const autocal::CalibrationModels m = autocal::read_models(models_path);
        o.start_model = selfcal::SystemModel{m.screen, m.camera, m.projectors};
    }
    const selfcal::SimulationReport r = selfcal::simulate(rig, o);
    if (verbose) {
        for (const auto& f : r.frames) {
            std::printf("t=%6.2f s  ground-truth error %.3f px  cpu %.1f ms  %s\n", f.t_s, f.geometry_mean_px, f.cpu_ms,
                        f.status.c_str());
        }
    }
    for (const std::string& line : r.journal) std::printf("journal: %s\n", line.c_str());
    std::printf(
        "rig %s, projector scale %.2f (errors in those projector pixels), camera scale %.2f, monitor %.2f Hz, "
        "%d frames (%.1f simulated s)\n",
        rig.name.c_str(), o.projector_scale, o.camera_scale, o.rate_hz, o.frames, o.frames / o.rate_hz);
    std::printf("error at the start: %.3f px (ground truth; %s)\n", r.start_error_px,
                models_path.empty() ? "the rig's exact models" : models_path.c_str());
    std::printf("error right after the bump: %.3f px (ground truth)\n", r.error_before_px);
    if (r.detected_after_s) std::printf("detected after: %.2f s\n", *r.detected_after_s);
    else std::printf("detected after: never\n");
    if (r.corrected_after_s)
        std::printf("corrected (< %.2f px) after: %.2f s\n", o.error_threshold_px, *r.corrected_after_s);
    else std::printf("corrected after: never\n");
    std::printf("final state: %s; corrections: %d; detections: %d; waiting frames: %d\n",
                selfcal::to_string(r.final_state), r.corrections, r.detections, r.waiting_frames);
    std::printf("final geometric error vs ground truth: mean %.3f px, p95 %.3f px\n", r.final_error_px, r.final_p95_px);
    std::printf("CPU per monitored frame: %.1f ms (%.1f %% of one core at %.2f Hz)\n", r.mean_cpu_ms,
                r.mean_cpu_ms * o.rate_hz / 10.0, o.rate_hz);
    return 0;
}

void add_simulate_flags(CLI::App& cmd, SelfcalCommand& f) {
    f.prior_mm = f.o.selfcal.monitor.projector_fit.prior_position_sd_m * 1e3;
    cmd.add_option("--rig", f.rig, "Virtual rig (rigs/*.toml)")->required()->check(CLI::ExistingFile);
    cmd.add_option("--bump", f.bumps,
                   "device:yaw=1deg,pitch=..,roll=..,x=5mm,y=..,z=.. (device: a projector id or camera)");
    cmd.add_option("--bump-at-s", f.bump_at_s, "simulated second of the bumps")->check(CLI::NonNegativeNumber);
    cmd.add_option("--rate-hz", f.o.rate_hz, "monitored frames per simulated second")->check(CLI::Range(0.01, 60.0));
    cmd.add_option("--frames", f.o.frames, "monitored frames")->check(CLI::Range(1, 100000));
    cmd.add_option("--projector-scale", f.o.projector_scale, "projector resolution scale")
        ->check(CLI::Range(0.05, 1.0));
    cmd.add_option("--camera-scale", f.o.camera_scale, "camera resolution scale")->check(CLI::Range(0.05, 1.0));
    cmd.add_option("--occlusion", f.o.occlusion, "fraction of the camera view hidden by visitors")
        ->check(CLI::Range(0.0, 0.9));
    cmd.add_option("--occlusion-max", f.o.occlusion_max, "each frame's occlusion uniform in [occlusion, this]")
        ->check(CLI::Range(0.0, 0.9));
    cmd.add_option("--hold-s", f.o.selfcal.hold_s, "seconds a drift must last before correcting")
        ->check(CLI::NonNegativeNumber);
    cmd.add_option("--transition-s", f.o.selfcal.transition_s, "seconds a correction is blended in over")
        ->check(CLI::NonNegativeNumber);
    cmd.add_option("--exposure-jitter", f.o.exposure_jitter, "camera gain varies in [1-j, 1+j]")
        ->check(CLI::Range(0.0, 0.9));
    cmd.add_option("--content-kind", f.content, "textured | plain | repetitive | dark")
        ->check(CLI::IsMember({"textured", "plain", "repetitive", "dark"}));
    cmd.add_option("--seed", f.o.seed, "noise and content seed");
    cmd.add_option("--threshold-px", f.o.selfcal.drift_threshold_px, "drift threshold, projector pixels")
        ->check(CLI::PositiveNumber);
    cmd.add_option("--owner-min-blend", f.o.selfcal.monitor.owner_min_blend,
                   "a match belongs to a projector from this blend weight")
        ->check(CLI::Range(0.5, 1.0));
    cmd.add_option("--unmix-max-shift-px", f.o.selfcal.monitor.unmix_max_shift_px,
                   "overlap matches shifted less than this (camera px) are un-mixed; 0 off")
        ->check(CLI::NonNegativeNumber);
    cmd.add_flag("--no-edge-check", f.no_edge_check,
                 "do not check the camera fit against the screen's edges (Monitor::edges_moved)");
    cmd.add_option("--occluder-ratio", f.o.selfcal.monitor.occluder_ratio,
                   "visitor mask: cells darker or brighter than predicted by this factor; 0 off")
        ->check(CLI::Range(0.0, 0.99));
    cmd.add_option("--occluder-cell-px", f.o.selfcal.monitor.occluder_cell_px, "visitor mask: cell size, camera pixels")
        ->check(CLI::Range(2, 256));
    cmd.add_option("--min-matches", f.o.selfcal.min_matches, "matches a projector needs for a measurement")
        ->check(CLI::Range(6, 100000));
    cmd.add_option("--position-prior-mm", f.prior_mm,
                   "projector fit's position prior, mm per pixel of residual (0 none)")
        ->check(CLI::NonNegativeNumber);
    cmd.add_flag("--pattern", f.o.selfcal.pattern.enabled,
                 "content-independent fallback: an imperceptible pattern pair when the content has too little texture");
    cmd.add_option("--pattern-amplitude", f.o.selfcal.pattern.amplitude, "the pattern's amplitude, linear content")
        ->check(CLI::Range(0.001, 0.2));
    cmd.add_option("--truth-every", f.o.truth_every, "ground truth every N frames (and at the last, around changes)")
        ->check(CLI::Range(1, 100000));
    cmd.add_flag("--verbose", f.verbose, "one line per monitored frame");
    cmd.add_option("--models", f.models,
                   "start from these models (a full calibration's estimate: mogao-calibrate-sim rig --rig RIG "
                   "--scale S writes calibration.models.json) instead of the rig's exact ones")
        ->check(CLI::ExistingFile);
}

}  // namespace

void add_selfcal_command(CLI::App& parent, SelfcalCommand& cmd) {
    cmd.app = parent.add_subcommand(
        "selfcal-simulate",
        "Self-recalibration on a virtual rig (simulation): bump devices and watch the monitor correct them");
    add_simulate_flags(*cmd.app, cmd);
}

int run_selfcal_command(SelfcalCommand f) {
    selfcal::SimulationOptions& o = f.o;
    o.content = f.content == "plain"        ? ContentKind::plain
                : f.content == "repetitive" ? ContentKind::repetitive
                : f.content == "dark"       ? ContentKind::dark
                                            : ContentKind::textured;
    o.selfcal.build.warp_step_px = 4;
    o.selfcal.monitor.check_edges = !f.no_edge_check;
    o.selfcal.monitor.projector_fit.prior_position_sd_m = f.prior_mm * 1e-3;
    try {
        return run_simulate(f.rig, f.models, f.bumps, f.bump_at_s, o, f.verbose);
    } catch (const std::invalid_argument& e) {
        std::fprintf(stderr, "mogao-calibrate-sim selfcal-simulate: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "mogao-calibrate-sim selfcal-simulate: %s\n", e.what());
        return 1;
    }
}

}  // namespace mogao::calibrate
