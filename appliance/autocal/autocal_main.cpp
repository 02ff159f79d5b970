// SPDX-License-Identifier: Apache-2.0
// mogao-autocal: camera-based calibration of a virtual rig (calibrate_job.h, docs/calibration.md).
//
//   mogao-autocal calibrate --rig rigs/standard.toml --out DIR [--scale 0.5] [--content 1920x1080]
//                 [--alpha-bits 16] [--warp-step-px 2] [--gray-bits N] [--frames-per-pattern 1] [--no-colour]
//                 [--no-falloff] [--fit-screen] [--no-bow] [--fixed-camera-intrinsics] [--intrinsics-min-gain 0.01]
//                 [--pinhole-projectors] [--distortion-min-gain 0.01] [--max-self-check-px 0.65]
//
// Exit codes: 0 success, 1 the job failed or the calibration was refused (the message says why;
// nothing in DIR changes), 2 bad command line.
#include <cstdio>
#include <iostream>

#include <CLI/CLI.hpp>

#include "appliance/autocal/calibrate_job.h"
#include "appliance/autocal/calibration_flags.h"
#include "common/program_cli.h"

namespace {

using mogao::autocal::CalibrateJob;

// The flags of `calibrate` beyond those mogao-calibrate shares (calibration_flags.h).
struct AutocalFlags {
    mogao::autocal::CalibrationFlags shared;
    bool fixed_intrinsics = false;
};

void add_autocal_flags(CLI::App& cmd, AutocalFlags& flags, CalibrateJob& job) {
    cmd.add_option("--rig", job.rig, "Virtual rig (rigs/*.toml)")->required()->check(CLI::ExistingFile);
    cmd.add_option("--out", job.out, "Output folder")->required();
    mogao::autocal::add_calibration_flags(cmd, flags.shared, job);
    cmd.add_option("--gray-bits", job.options.max_gray_bits,
                   "Gray-code bits shown per axis, 0 = all (down to the finest stripe); else 4..16")
        ->check(CLI::Range(0, 16));
    cmd.add_option("--frames-per-pattern", job.options.frames_per_pattern,
                   "Camera frames averaged per structured-light pattern, 1..64")
        ->check(CLI::Range(1, 64));
    cmd.add_option("--phase-shifts", job.options.phase_shifts,
                   "Phase-shifted sinusoids per axis on top of the Gray code, 0 = off, else 3..16")
        ->check(CLI::Range(0, 16));
    cmd.add_option("--phase-period-px", job.options.phase_period_px, "Phase-shift period, projector pixels, 4..1024")
        ->check(CLI::Range(4.0, 1024.0));
    cmd.add_flag("--fixed-camera-intrinsics", flags.fixed_intrinsics,
                 "Take the camera's intrinsics as exact: do not try refining its focal length, principal point and "
                 "k1, k2 (kept by default only where they pay)");
    cmd.add_option("--intrinsics-min-gain", job.options.intrinsics_min_gain,
                   "Keep the refined camera intrinsics only where the fit's cost falls by more than this fraction "
                   "(0: whenever it falls)")
        ->check(CLI::Range(0.0, 0.99));
    cmd.add_option("--distortion-min-gain", job.options.distortion_min_gain,
                   "Keep a projector's fitted lens distortion only where its fit's cost falls by more than this "
                   "fraction (0: whenever it falls)")
        ->check(CLI::Range(0.0, 0.99));
}

void print_report(const nlohmann::json& r, const CalibrateJob& job) {
    const auto& t = r["ground_truth"];
    const auto& c = r["self_check"];
    std::printf(
        "%s: self-check (no ground truth): marks landed %.3f px mean, p95 %.3f px (%.1f mm) from where they "
        "belong, %d of %d marks measured; gate %.2f px\n",
        r["rig"].get<std::string>().c_str(), c["mean_px"].get<double>(), c["p95_px"].get<double>(),
        c["mean_mm"].get<double>(), c["marks_found"].get<int>(), c["marks_shown"].get<int>(),
        c["gate_max_mean_px"].get<double>());
    std::printf("%s: geometry mean %.3f p95 %.3f px, seam luminance %.2f %% (against the rig's ground truth); %s\n",
                r["rig"].get<std::string>().c_str(), t["geometry_mean_px"].get<double>(),
                t["geometry_p95_px"].get<double>(), 100.0 * t["seam_luminance_max_deviation"].get<double>(),
                job.out.c_str());
    for (const auto& s : t["seams"]) {
        std::printf(
            "  content %.2f: seam luminance deviation %.2f %%, seam Delta E76 %.2f (max over the screen %.2f)\n",
            s["level"].get<double>(), 100.0 * s["seam_luminance_deviation"].get<double>(),
            s["seam_delta_e76"].get<double>(), s["delta_e76_max"].get<double>());
    }
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Camera-based projector calibration on a virtual rig (docs/calibration.md)"};
    mogao::cli::prepare(app, "mogao-autocal");
    app.require_subcommand(1);
    CalibrateJob job;
    AutocalFlags flags;
    CLI::App* cmd = app.add_subcommand("calibrate", "Calibrate a rig: MPCDI, report.json and preview.png into --out");
    add_autocal_flags(*cmd, flags, job);
    try {
        app.parse(argc, argv);
        mogao::autocal::apply_calibration_flags(flags.shared, job);
        job.options.refine_camera_intrinsics = !flags.fixed_intrinsics;
    } catch (const CLI::ParseError& e) {
        return mogao::cli::exit_status(app, e);
    }
    try {
        print_report(mogao::autocal::run_calibrate_job(job), job);
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "mogao-autocal calibrate: " << e.what() << "\n";
        return 1;
    }
}
