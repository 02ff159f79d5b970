// SPDX-License-Identifier: Apache-2.0
// mogao-autocal: camera-based calibration of a virtual rig (calibrate_job.h, docs/calibration.md).
//
//   mogao-autocal calibrate --rig rigs/standard.toml --out DIR [--scale 0.5] [--content 1920x1080]
//                 [--alpha-bits 16] [--warp-step 2] [--gray-bits N] [--frames-per-pattern 1] [--no-colour]
//                 [--no-falloff] [--fit-screen] [--no-bow] [--fixed-camera-intrinsics] [--intrinsics-min-gain 0.01]
//                 [--pinhole-projectors] [--distortion-min-gain 0.01] [--max-self-check-px 0.65]
//
// Exit codes: 0 success, 1 the job failed or the calibration was refused (the message says why;
// nothing in DIR changes), 2 bad command line.
#include <cstdio>
#include <iostream>

#include <CLI/CLI.hpp>

#include "appliance/autocal/calibrate_job.h"
#include "common/program_cli.h"

int main(int argc, char** argv) {
    CLI::App app{"Camera-based projector calibration on a virtual rig (docs/calibration.md)"};
    mogao::cli::prepare(app, "mogao-autocal");
    app.require_subcommand(1);
    mogao::autocal::CalibrateJob job;
    std::string content = "1920x1080";
    CLI::App* cmd = app.add_subcommand("calibrate", "Calibrate a rig: MPCDI, report.json and preview.png into --out");
    cmd->add_option("--rig", job.rig, "Rig file (rigs/*.toml)")->required()->check(CLI::ExistingFile);
    cmd->add_option("--out", job.out, "Output folder")->required();
    cmd->add_option("--scale", job.scale, "Resolution scale of projectors and camera, (0, 1]")
        ->check(CLI::Range(0.05, 1.0));
    cmd->add_option("--content", content, "Content frame WIDTHxHEIGHT (the farm's frame)");
    cmd->add_option("--alpha-bits", job.alpha_bits, "Alpha map bits, 8 or 16")->check(CLI::IsMember({8, 16}));
    cmd->add_option("--warp-step", job.options.warp_step_px, "Warp grid step, output pixels")->check(CLI::Range(1, 64));
    cmd->add_option("--gray-bits", job.options.max_gray_bits,
                    "Gray-code bits shown per axis, 0 = all (finest stripe 1 px); else 4..16")
        ->check(CLI::Range(0, 16));
    cmd->add_option("--frames-per-pattern", job.options.frames_per_pattern,
                    "Camera frames averaged per structured-light pattern, 1..64")
        ->check(CLI::Range(1, 64));
    cmd->add_option("--phase-shifts", job.options.phase_shifts,
                    "Phase-shifted sinusoids per axis on top of the Gray code, 0 = off, else 3..16")
        ->check(CLI::Range(0, 16));
    cmd->add_option("--phase-period", job.options.phase_period_px, "Phase-shift period, projector pixels, 4..1024")
        ->check(CLI::Range(4.0, 1024.0));
    cmd->add_flag("--fit-screen", job.options.fit_screen,
                  "Fit the screen's radius and arc too (known only roughly; the heights are taken as measured)");
    bool no_bow = false;
    cmd->add_flag("--no-bow", no_bow,
                  "Take the screen as an exact cylinder: do not try a bow (kept by default only where it pays)");
    bool fixed_intrinsics = false;
    cmd->add_flag("--fixed-camera-intrinsics", fixed_intrinsics,
                  "Take the camera's intrinsics as exact: do not try refining its focal length, principal point and "
                  "k1, k2 (kept by default only where they pay)");
    cmd->add_option("--intrinsics-min-gain", job.options.intrinsics_min_gain,
                    "Keep the refined camera intrinsics only where the fit's cost falls by more than this fraction "
                    "(0: whenever it falls)")
        ->check(CLI::Range(0.0, 0.99));
    bool pinhole = false;
    cmd->add_flag("--pinhole-projectors", pinhole,
                  "Take the projectors as pinholes: do not try fitting their lens distortion (kept by default, per "
                  "projector, only where it pays)");
    cmd->add_option("--distortion-min-gain", job.options.distortion_min_gain,
                    "Keep a projector's fitted lens distortion only where its fit's cost falls by more than this "
                    "fraction (0: whenever it falls)")
        ->check(CLI::Range(0.0, 0.99));
    cmd->add_option("--max-self-check-px", job.self_check.max_mean_px,
                    "Self-check gate: refuse when the verification marks land further than this from where they "
                    "belong (mean, projector pixels; measured from the camera images against the screen's frame)")
        ->check(CLI::PositiveNumber);
    bool no_colour = false;
    cmd->add_flag("--no-colour", no_colour, "Geometry only: no response, black-level and colour matching step");
    bool no_falloff = false;
    cmd->add_flag("--no-falloff", no_falloff,
                  "Colour step without the lens fall-off: one gain per projector and channel (flat projectors)");
    try {
        app.parse(argc, argv);
        job.colour = !no_colour;
        job.colour_options.lens_falloff = !no_falloff;
        job.options.fit_bow = !no_bow;
        job.options.refine_camera_intrinsics = !fixed_intrinsics;
        job.options.fit_projector_distortion = !pinhole;
        if (std::sscanf(content.c_str(), "%dx%d", &job.content.width, &job.content.height) != 2 ||
            job.content.width < 1 || job.content.height < 1 || job.content.width > 16384 ||
            job.content.height > 16384) {
            throw CLI::ValidationError("--content", "must be WIDTHxHEIGHT, 1..16384 per side");
        }
    } catch (const CLI::ParseError& e) {
        return mogao::cli::exit_status(app, e);
    }
    try {
        const nlohmann::json r = mogao::autocal::run_calibrate_job(job);
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
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "mogao-autocal calibrate: " << e.what() << "\n";
        return 1;
    }
}
