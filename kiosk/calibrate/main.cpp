// SPDX-License-Identifier: Apache-2.0
// mogao-calibrate: camera-based calibration of the projector wall (docs/on-site-calibration.md).
//
//   On site (the kiosk stopped: it holds the outputs):
//     mogao-calibrate --site /etc/mogao/site.toml --outputs kms --camera v4l2:/dev/video0
//                     --out /var/lib/mogao/calibration [--install /var/lib/mogao/etc/screen.mpcdi]
//   On a virtual rig (tests, benchmarks; what `mogao-autocal calibrate` does, ground truth reported):
//     mogao-calibrate-sim --rig rigs/standard.toml --out DIR [--scale 0.5]
//   The whole on-site path without hardware (SIMULATION: the rig's camera films the headless outputs,
//   or with --outputs kms the kernel's scanout buffers: the appliance image's QEMU test):
//     mogao-calibrate-sim --site rigs/standard.toml --outputs headless --camera rig:rigs/standard.toml --out DIR
//   (mogao-calibrate-sim: this program with the routes of simulation_routes.h; the shipped mogao-calibrate
//   refuses them, exit 2.)
//   From images captured by any camera: write the patterns, show and film each, then calibrate:
//     mogao-calibrate patterns --site FILE --out DIR [--scale S] [--phase-periods-px P[,P...]]
//     mogao-calibrate --site FILE --images DIR --out DIR [--install FILE] [--camera-transfer srgb|linear]
//   Projector intrinsics on the bench from Gray-code captures of a board (docs/calibration.md):
//     mogao-calibrate procam --pose-images DIR [DIR...] --projector-size WxH --board COLSxROWS --square-mm S --out
//     FILE.json
//   How many images and how long the capture takes:
//     mogao-calibrate --site FILE --budget [--camera-fps 30 --settle-ms 150 --drop-frames 2]
//
// Exit codes: 0 success, 1 refused or failed (the message says why; the last good calibration is
// untouched), 2 bad command line.
#include <unistd.h>

#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "appliance/autocal/calibrate_job.h"
#include "appliance/autocal/calibration_flags.h"
#include "common/program_cli.h"
#include "drivers/headless/headless_output.h"
#include "drivers/kms/kms_backend.h"
#include "kiosk/calibrate/images_job.h"
#include "kiosk/calibrate/on_site_job.h"
#include "kiosk/calibrate/pattern_budget.h"
#include "kiosk/calibrate/patterns_command.h"
#include "kiosk/calibrate/procam_command.h"
#include "kiosk/calibrate/simulation_routes.h"

namespace {

using namespace mogao;
using namespace mogao::calibrate;

struct Cli {
    std::filesystem::path rig;
    std::filesystem::path site;
    std::string outputs;
    std::string camera;
    std::filesystem::path images;
    std::filesystem::path kms_device;
    autocal::CalibrationFlags shared;  // calibration_flags.h
    std::string camera_size;
    int camera_fps = 0;
    double exposure_us = 0.0;
    double gain = -1.0;
    double white_balance_k = 0.0;
    std::string transfer = "srgb";
    bool grey = false;
    bool budget = false;
    double budget_fps = 30.0;
};

// Help texts of flags other programs declare too, word for word (one text per name, docs/cli.md;
// the test cli_flag_names compares them): the capture device as mogao-track navigate takes it, the
// DRM card as mogao-kms-probe does.
constexpr const char* kCameraHelp =
    "Capture device: v4l2:/dev/videoN (or /dev/videoN) or libcamera:[id]; mogao-calibrate also replay:DIR and "
    "rig:FILE (simulation: mogao-calibrate-sim)";
constexpr const char* kKmsDeviceHelp =
    "DRM card node /dev/dri/cardN (default: mogao-calibrate the first with a connected connector, mogao-kms-probe "
    "every card)";

bool parse_size(const std::string& text, ImageSize& out) {
    return std::sscanf(text.c_str(), "%dx%d", &out.width, &out.height) == 2 && out.width >= 1 && out.height >= 1 &&
           out.width <= 16384 && out.height <= 16384;
}

void print_progress(const CaptureProgress& p) {
    static const bool tty = ::isatty(STDERR_FILENO) != 0;
    const int step = std::max(1, p.expected / 20);
    if (!tty && p.done % step != 0 && p.done != p.expected) return;
    const int bar = 30 * p.done / std::max(1, p.expected);
    std::fprintf(stderr, "%s[%s%s] %d/%d images, %.2f s each, about %.0f s left%s", tty ? "\r" : "",
                 std::string(static_cast<std::size_t>(bar), '#').c_str(),
                 std::string(static_cast<std::size_t>(30 - bar), '.').c_str(), p.done, p.expected, p.seconds_per_image,
                 p.seconds_left, tty ? "" : "\n");
}

int run_rig(const Cli& cli, const OnSiteJob& site_job) {
    autocal::CalibrateJob job;
    job.rig = cli.rig;
    job.out = site_job.out;
    job.scale = site_job.scale;
    job.content = site_job.content;
    job.alpha_bits = site_job.alpha_bits;
    job.options = site_job.options;
    job.colour = site_job.colour;
    job.colour_options = site_job.colour_options;
    job.self_check = site_job.self_check;
    return run_rig_calibration(job);
}

int run_budget(const Cli& cli, const OnSiteJob& job) {
    const autocal::CalibrationPrior prior = site_prior(job);
    const PatternBudget b = pattern_budget(prior, job.colour, job.colour_options, job.options, job.self_check);
    const double each = seconds_per_image(cli.budget_fps, job.timing.settle_ms, job.timing.drop_frames);
    std::printf(
        "%zu projectors: %d images (identification %d, geometry at most %d, colour %d, self-check %d); at %.0f fps, "
        "settle %d ms, %d frames dropped: %.3f s per image, %.0f s (%.1f min) of capture\n",
        prior.projectors.size(), b.total(), b.identification, b.geometry, b.colour, b.self_check, cli.budget_fps,
        job.timing.settle_ms, job.timing.drop_frames, each, each * b.total(), each * b.total() / 60.0);
    return 0;
}

std::unique_ptr<OutputBackend> open_outputs(const Cli& cli, const autocal::CalibrationPrior& prior) {
    if (cli.outputs == "kms") {
        auto kms = KmsOutputBackend::create(KmsOptions{cli.kms_device});
        if (!kms) throw std::runtime_error("KMS outputs: " + kms.error().message + " (is mogao-kiosk stopped?)");
        return std::move(kms.value());
    }
    HeadlessOptions h;
    for (const autocal::DeviceModel& p : prior.projectors) h.outputs.push_back(p.resolution);
    auto headless = HeadlessOutputBackend::create(std::move(h));
    if (!headless) throw std::runtime_error("headless outputs: " + headless.error().message);
    return std::move(headless.value());
}

std::unique_ptr<CalibrationCamera> open_live_camera(const Cli& cli, const autocal::CalibrationPrior& prior) {
    CameraSourceSpec spec;
    std::string why;
    // "/dev/videoN" alone is V4L2, as mogao-track navigate takes it.
    const std::string named = cli.camera.starts_with("/") ? "v4l2:" + cli.camera : cli.camera;
    if (!parse_camera_source(named, spec, &why)) throw std::invalid_argument("--camera: " + why);
    ImageSize size = prior.camera.resolution;
    if (!cli.camera_size.empty() && !parse_size(cli.camera_size, size)) {
        throw std::invalid_argument("--camera-size must be WIDTHxHEIGHT");
    }
    spec.width = size.width;
    spec.height = size.height;
    spec.fps = cli.camera_fps;
    spec.colour = !cli.grey;
    if (cli.exposure_us > 0)
        spec.controls.exposure = {ControlSetting::Mode::manual, cli.exposure_us, true, "--exposure-us"};
    if (cli.gain >= 0) spec.controls.gain = {ControlSetting::Mode::manual, cli.gain, true, "--gain"};
    if (cli.white_balance_k > 0) {
        spec.controls.white_balance = {ControlSetting::Mode::manual, cli.white_balance_k, true, "--white-balance-k"};
    }
    auto camera = open_calibration_camera(spec);
    if (!camera) throw autocal::CalibrationRefused(camera.error().message);
    return std::move(camera.value());
}

int run_site(const Cli& cli, OnSiteJob& job) {
    const autocal::CalibrationPrior prior = site_prior(job);
    // A live camera first: one whose exposure cannot be locked is refused before the outputs light.
    const bool simulated = cli.camera.starts_with("rig:");
    std::unique_ptr<CalibrationCamera> camera;
    if (!simulated) camera = open_live_camera(cli, prior);
    std::unique_ptr<OutputBackend> outputs = open_outputs(cli, prior);
    if (simulated) camera = open_rig_camera(cli.camera.substr(4), job.scale, *outputs);
    std::fprintf(stderr, "mogao-calibrate: camera %s; %zu outputs\n", camera->description().c_str(),
                 outputs->outputs().size());
    const nlohmann::json r = run_on_site(job, *outputs, *camera, print_progress);
    std::printf("%d images in %.1f s (%.3f s each); connectors:", r["captures"].get<int>(),
                r["capture_seconds"].get<double>(), r["seconds_per_image"].get<double>());
    for (const auto& c : r["connectors"]) {
        std::printf(" %s=%s", c["projector"].get<std::string>().c_str(), c["connector"].get<std::string>().c_str());
    }
    std::printf("\n");
    for (const auto& change : r["cabling_changes"])
        std::printf("cabling changed: %s\n", change.get<std::string>().c_str());
    for (const auto& p : r["projectors"]) {
        std::printf("  %s: %d x %d Gray bits, %d correspondences, reprojection rms %.3f px\n",
                    p["id"].get<std::string>().c_str(), p["column_bits"].get<int>(), p["row_bits"].get<int>(),
                    p["correspondences"].get<int>(), p["reprojection_rms_px"].get<double>());
    }
    const auto& check = r["self_check"];
    std::printf(
        "self-check: marks landed %.2f px mean, p95 %.2f px (%.1f mm) from where their content belongs, "
        "%d of %d marks measured (gate %.2f px)\n",
        check["mean_px"].get<double>(), check["p95_px"].get<double>(), check["mean_mm"].get<double>(),
        check["marks_found"].get<int>(), check["marks_shown"].get<int>(), check["gate_max_mean_px"].get<double>());
    std::printf("written to %s%s%s\n", job.out.c_str(), job.install.empty() ? "" : " and ", job.install.c_str());
    if (simulated) print_simulation_truth(cli.camera.substr(4), job.scale, job.out / "calibration.mpcdi");
    return 0;
}

int run_images(const Cli& cli, const OnSiteJob& job) {
    const nlohmann::json r = run_from_images(job, cli.images);
    std::printf("%d captured images of %d patterns (geometry only: no colour step from captures)\n",
                r["captures"].get<int>(), r["images"]["patterns"].get<int>());
    for (const auto& p : r["projectors"]) {
        std::printf("  %s: %d x %d Gray bits, %d correspondences, reprojection rms %.3f px\n",
                    p["id"].get<std::string>().c_str(), p["column_bits"].get<int>(), p["row_bits"].get<int>(),
                    p["correspondences"].get<int>(), p["reprojection_rms_px"].get<double>());
    }
    std::printf("written to %s%s%s\n", job.out.c_str(), job.install.empty() ? "" : " and ", job.install.c_str());
    return 0;
}

// The flags of the calibration itself (on site, from images, on a rig); `procam` and `patterns` add their own.
void add_calibrate_flags(CLI::App& app, Cli& cli, OnSiteJob& job) {
    auto* rig = app.add_option("--rig", cli.rig, "Virtual rig (rigs/*.toml)")->check(CLI::ExistingFile);
    auto* site = app.add_option("--site", cli.site, "Site file (rig format): the installation as measured")
                     ->check(CLI::ExistingFile);
    rig->excludes(site);
    app.add_option("--out", job.out, "Output folder");
    app.add_option("--outputs", cli.outputs, "kms or headless")->check(CLI::IsMember({"kms", "headless"}));
    app.add_option("--camera", cli.camera, kCameraHelp);
    app.add_option("--images", cli.images,
                   "Folder of captured images with captures.json (`patterns`): calibrate from them, no outputs or "
                   "camera driven")
        ->check(CLI::ExistingDirectory)
        ->excludes(rig);
    app.add_option("--install", job.install, "Also write the MPCDI here (the kiosk's [calibration].source)");
    app.add_option("--kms-device", cli.kms_device, kKmsDeviceHelp);
    autocal::add_calibration_flags(app, cli.shared, job);
    app.add_option("--camera-size", cli.camera_size, "Camera WIDTHxHEIGHT (default: the site file's camera)");
    app.add_option("--camera-fps", cli.camera_fps, "Camera frame rate to ask for (0: the driver's)")
        ->check(CLI::Range(0, 1000));
    app.add_option("--exposure-us", cli.exposure_us, "Manual exposure, us (default: lock the current one)")
        ->check(CLI::Range(1.0, 1e6));
    app.add_option("--gain", cli.gain, "Manual gain, device units (default: lock)")->check(CLI::Range(0.0, 1e6));
    app.add_option("--white-balance-k", cli.white_balance_k, "Manual white balance, K (default: lock)")
        ->check(CLI::Range(1000.0, 20000.0));
    app.add_option("--camera-transfer", cli.transfer, "Camera codes: srgb (decoded) or linear")
        ->check(CLI::IsMember({"srgb", "linear"}));
    app.add_flag("--grey", cli.grey, "Use the camera's luma instead of colour frames");
    app.add_option("--settle-ms", job.timing.settle_ms, "Wait after each flip, ms")->check(CLI::Range(0, 10000));
    app.add_option("--drop-frames", job.timing.drop_frames, "Camera frames dropped after the settle")
        ->check(CLI::Range(0, 30));
    app.add_flag("--budget", cli.budget, "Print the image count and capture time for --site, then exit");
    app.add_option("--budget-fps", cli.budget_fps, "Camera frame rate for --budget")->check(CLI::Range(1.0, 1000.0));
}

// After the parse: what CLI11 cannot check, and the flags into the job. Throws CLI::ValidationError.
void apply_calibrate_flags(const Cli& cli, OnSiteJob& job) {
    autocal::apply_calibration_flags(cli.shared, job);
    if (cli.rig.empty() && cli.site.empty()) throw CLI::ValidationError("--rig or --site", "one is required");
    if (!has_simulation_routes() && (!cli.rig.empty() || cli.camera.starts_with("rig:"))) {
        throw CLI::ValidationError(
            "--rig and --camera rig:FILE",
            "are simulation: mogao-calibrate-sim has them (built with the tests, not installed)");
    }
    if (!cli.budget && job.out.empty()) throw CLI::ValidationError("--out", "is required");
    if (!cli.images.empty() && (!cli.outputs.empty() || !cli.camera.empty() || cli.budget)) {
        throw CLI::ValidationError("--images", "replaces --outputs and --camera (and is no --budget)");
    }
    if (!cli.site.empty() && !cli.budget && cli.images.empty() && (cli.outputs.empty() || cli.camera.empty())) {
        throw CLI::ValidationError("--site", "needs --outputs and --camera, or --images (or --budget)");
    }
    job.site = cli.site;
    job.transfer =
        cli.transfer == "linear" || cli.camera.starts_with("rig:") ? CameraTransfer::linear : CameraTransfer::srgb;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Camera-based calibration of the projector wall (docs/on-site-calibration.md)"};
    mogao::cli::prepare(app, "mogao-calibrate");
    Cli cli;
    OnSiteJob job;
    add_calibrate_flags(app, cli, job);
    ProcamCommand procam;
    add_procam_command(app, procam);
    PatternsCommand patterns;
    add_patterns_command(app, patterns);
    try {
        app.parse(argc, argv);
        if (procam.app->parsed()) return run_procam_command(procam);
        if (patterns.app->parsed()) return run_patterns_command(patterns);
        apply_calibrate_flags(cli, job);
    } catch (const CLI::ParseError& e) {
        return mogao::cli::exit_status(app, e);
    }
    try {
        if (!cli.rig.empty()) return run_rig(cli, job);
        if (cli.budget) return run_budget(cli, job);
        if (!cli.images.empty()) return run_images(cli, job);
        return run_site(cli, job);
    } catch (const std::exception& e) {
        std::cerr << "\nmogao-calibrate: " << e.what() << "\n";
        return 1;
    }
}
