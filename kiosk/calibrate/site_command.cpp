// SPDX-License-Identifier: Apache-2.0
// `mogao-calibrate [site]`: the on-site job's command line (site_command.h).
#include "kiosk/calibrate/site_command.h"

#include <unistd.h>

#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "common/size_text.h"
#include "drivers/headless/headless_output.h"
#include "drivers/kms/kms_backend.h"
#include "kiosk/calibrate/images_job.h"
#include "kiosk/calibrate/pattern_budget.h"
#include "kiosk/calibrate/simulation_routes.h"

namespace mogao::calibrate {
namespace {

using Cli = SiteCommand;

// Help texts of flags other programs declare too, word for word (one text per name, docs/cli.md;
// the test cli_flag_names compares them): the capture device as mogao-track navigate takes it, the
// DRM card as mogao-kms-probe does.
constexpr const char* kCameraHelp =
    "Capture device: v4l2:/dev/videoN (or /dev/videoN) or libcamera:[id]; mogao-calibrate also replay:DIR and "
    "rig:FILE (simulation: mogao-calibrate-sim)";
constexpr const char* kKmsDeviceHelp =
    "DRM card node /dev/dri/cardN (default: mogao-calibrate the first with a connected connector, mogao-kms-probe "
    "every card)";

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

int run_budget(const Cli& cli) {
    const OnSiteJob& job = cli.job;
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
    if (!cli.camera_size.empty() && !parse_size(cli.camera_size, size, 1, 16384)) {
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

int run_site(const Cli& cli) {
    const OnSiteJob& job = cli.job;
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

int run_images(const Cli& cli) {
    const OnSiteJob& job = cli.job;
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

// The flags of the on-site job (from a camera or from images).
void add_site_flags(CLI::App& app, Cli& cli) {
    OnSiteJob& job = cli.job;
    app.add_option("--site", cli.site, "Site file (rig format): the installation as measured")
        ->check(CLI::ExistingFile);
    app.add_option("--out", job.out, "Output folder");
    app.add_option("--outputs", cli.outputs, "kms or headless")->check(CLI::IsMember({"kms", "headless"}));
    app.add_option("--camera", cli.camera, kCameraHelp);
    app.add_option("--images", cli.images,
                   "Folder of captured images with captures.json (`patterns`): calibrate from them, no outputs or "
                   "camera driven")
        ->check(CLI::ExistingDirectory);
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

}  // namespace

void add_site_command(CLI::App& parent, SiteCommand& cmd) {
    add_site_flags(parent, cmd);
    cmd.app = parent.add_subcommand("site", "The on-site calibration (the default: the same flags without `site`)");
    add_site_flags(*cmd.app, cmd);
}

void check_site_command(SiteCommand& cli) {
    OnSiteJob& job = cli.job;
    autocal::apply_calibration_flags(cli.shared, job);
    if (cli.site.empty()) throw CLI::ValidationError("--site", "is required (or a subcommand)");
    if (!has_simulation_routes() && cli.camera.starts_with("rig:")) {
        throw CLI::ValidationError("--camera rig:FILE",
                                   "is simulation: mogao-calibrate-sim has it (built with the tests, not installed)");
    }
    if (!cli.budget && job.out.empty()) throw CLI::ValidationError("--out", "is required");
    if (!cli.images.empty() && (!cli.outputs.empty() || !cli.camera.empty() || cli.budget)) {
        throw CLI::ValidationError("--images", "replaces --outputs and --camera (and is no --budget)");
    }
    if (!cli.budget && cli.images.empty() && (cli.outputs.empty() || cli.camera.empty())) {
        throw CLI::ValidationError("--site", "needs --outputs and --camera, or --images (or --budget)");
    }
    job.site = cli.site;
    job.transfer =
        cli.transfer == "linear" || cli.camera.starts_with("rig:") ? CameraTransfer::linear : CameraTransfer::srgb;
}

int run_site_command(const SiteCommand& cli) {
    try {
        if (cli.budget) return run_budget(cli);
        if (!cli.images.empty()) return run_images(cli);
        return run_site(cli);
    } catch (const std::exception& e) {
        std::cerr << "\nmogao-calibrate: " << e.what() << "\n";
        return 1;
    }
}

}  // namespace mogao::calibrate
