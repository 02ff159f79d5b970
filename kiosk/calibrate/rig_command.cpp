// SPDX-License-Identifier: Apache-2.0
// `mogao-calibrate-sim rig` (rig_command.h).
#include "kiosk/calibrate/rig_command.h"

#include <cstdio>
#include <iostream>

#include "appliance/rig/rig_file.h"
#include "kiosk/calibrate/procam_command.h"

namespace mogao::calibrate {
namespace {

using autocal::CalibrateJob;

void add_rig_flags(CLI::App& cmd, RigCommand& flags, CalibrateJob& job) {
    cmd.add_option("--rig", job.rig, "Virtual rig (rigs/*.toml)")->required()->check(CLI::ExistingFile);
    cmd.add_option("--out", job.out, "Output folder")->required();
    autocal::add_calibration_flags(cmd, flags.shared, job);
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
    // The site's flag, the same text (one meaning per flag name, docs/cli.md): the rig settles at once, so its
    // frames are dropped right after each pattern change (a rig camera with camera.straddle needs one).
    cmd.add_option("--drop-frames", job.drop_frames, "Camera frames dropped after the settle")
        ->check(CLI::Range(0, 30));
    // The truth is the screen's light through the rig's defocus (blur_px) unless this flag is given.
    cmd.add_flag_callback(
        "--sharp-truth", [&job] { job.defocused_truth = false; },
        "Ground truth: each projector pixel's light as a sharp step, not spread by the rig's defocus (blur_px) as "
        "the screen shows it");
    cmd.add_flag_callback(
        "--coarse-seams", [&job] { job.dense_seams = false; },
        "Ground truth: the seams at each content level on 401 x 101 points, not on a point per projector pixel "
        "(faster at full resolution; a line one pixel wide can fall between them)");
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

void add_rig_command(CLI::App& parent, RigCommand& cmd) {
    cmd.app = parent.add_subcommand(
        "rig",
        "Calibrate a virtual rig (simulation): MPCDI, report.json and preview.png into --out, against its ground "
        "truth");
    add_rig_flags(*cmd.app, cmd, cmd.job);
    cmd.app->parse_complete_callback([&cmd] {
        autocal::apply_calibration_flags(cmd.shared, cmd.job);
        cmd.job.options.refine_camera_intrinsics = !cmd.fixed_intrinsics;
    });
}

int run_rig_command(const RigCommand& cmd) {
    try {
        autocal::CalibrateJob job = cmd.job;
        job.bench_lenses = bench_lenses_of(rig::load_rig(job.rig), job.rig.string());
        print_report(autocal::run_calibrate_job(job), job);
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "mogao-calibrate-sim rig: " << e.what() << "\n";
        return 1;
    }
}

}  // namespace mogao::calibrate
