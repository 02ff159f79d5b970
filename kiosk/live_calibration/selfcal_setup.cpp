// SPDX-License-Identifier: Apache-2.0
#include "kiosk/live_calibration/selfcal_setup.h"

#include <array>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "appliance/autocal/model_store.h"
#include "common/srgb.h"
#include "drivers/camera/camera_source.h"
#include "kiosk/loop/kiosk_setup.h"

namespace mogao {
namespace {

[[noreturn]] void refuse(const std::string& message) { throw KioskSetupError(1, "selfcal: " + message); }

// A real V4L2 camera with its exposure and gain locked (or manual), at the models' camera size.
SelfcalWorker::Camera v4l2_camera(const SelfcalConfig& sc, const selfcal::SystemModel& model) {
    CameraSourceSpec spec = sc.source;
    const ImageSize want = model.camera.resolution;
    if (spec.width == 0) {
        spec.width = want.width;
        spec.height = want.height;
    } else if (spec.width != want.width || spec.height != want.height) {
        refuse(fmt::format("[selfcal].camera_size = {}x{} differs from the models' camera ({}x{}, {})", spec.width,
                           spec.height, want.width, want.height, sc.models.string()));
    }
    auto opened = open_camera_source(spec);
    if (!opened) refuse(fmt::format("[selfcal].camera '{}': {}", sc.camera, opened.error().message));
    std::shared_ptr<FrameSource> source = std::move(opened).value();
    spdlog::info("selfcal: screen camera {} (exposure {}, gain {})", source->description(),
                 describe(spec.controls.exposure), describe(spec.controls.gain));
    const std::array<float, 256>& decode = srgb8_decode_table();
    return [source, decode, want](const cv::Mat1f&, const ScreenCalibration&, std::uint64_t) {
        auto frame = source->next_frame();
        if (!frame) throw std::runtime_error("screen camera: " + frame.error().message);
        const GrayImage& g = frame->image;
        if (g.width != want.width || g.height != want.height) {
            throw std::runtime_error(fmt::format("screen camera: a {}x{} frame, the models' camera is {}x{}", g.width,
                                                 g.height, want.width, want.height));
        }
        cv::Mat1f out(g.height, g.width);
        for (int y = 0; y < g.height; ++y) {
            for (int x = 0; x < g.width; ++x) out(y, x) = decode[g.at(x, y)];
        }
        return out;
    };
}

selfcal::SystemModel read_system_model(const SelfcalConfig& sc, const ScreenCalibration& wall) {
    autocal::CalibrationModels m;
    try {
        m = autocal::read_models(sc.models);
        autocal::check_models_match(m, wall, sc.models.string());
    } catch (const autocal::ModelStoreError& e) {
        refuse(fmt::format("[selfcal].models: {}", e.what()));
    }
    return {m.screen, m.camera, m.projectors};
}

}  // namespace

std::optional<int> warp_step_of(const ScreenCalibration& calibration) {
    for (int step = 1; step <= 64; ++step) {
        bool all = true;
        for (const ProjectorCalibration& p : calibration.projectors) {
            const ImageSize grid{std::max(2, (p.output.width + step - 1) / step),
                                 std::max(2, (p.output.height + step - 1) / step)};
            all = all && grid.width == p.warp.size.width && grid.height == p.warp.size.height &&
                  grid.width == p.blend.size.width && grid.height == p.blend.size.height;
        }
        if (all) return step;
    }
    return std::nullopt;
}

std::unique_ptr<SelfcalWorker> start_selfcal(const SelfcalConfig& sc, const std::filesystem::path& mpcdi,
                                             const ScreenCalibration& wall, CalibrationInbox& inbox,
                                             const SimulatedScreenCamera& simulated) {
    if (!sc.enabled) return nullptr;
    const selfcal::SystemModel model = read_system_model(sc, wall);
    selfcal::SelfcalOptions options;
    options.hold_s = sc.hold_s;
    options.transition_s = sc.transition_s;
    options.drift_threshold_px = sc.drift_threshold_px;
    options.pattern.enabled = sc.pattern;
    options.pattern.amplitude = sc.pattern_amplitude;
    options.store = mpcdi;             // corrections written back; the watcher sees the same file
    options.models_store = sc.models;  // and the corrected poses beside it, for the next start
    const std::optional<int> step = warp_step_of(wall);
    if (!step) {
        refuse(
            fmt::format("{}: its warp grids are not ones mogao-calibrate builds (a grid step of 1..64 pixels): "
                        "self-recalibration cannot blend a correction into them",
                        mpcdi.string()));
    }
    options.build.warp_step_px = *step;
    if (sc.kind == SelfcalConfig::CameraKind::rig && !simulated) {
        refuse(
            fmt::format("[selfcal].camera '{}' is a simulation of the virtual rig, which this mogao-kiosk (the "
                        "appliance's build) does not carry: use a v4l2: camera, or mogao-kiosk-sim for tests "
                        "and demos",
                        sc.camera));
    }
    SelfcalWorker::Camera camera =
        sc.kind == SelfcalConfig::CameraKind::rig ? simulated(sc, model) : v4l2_camera(sc, model);
    try {
        auto worker = std::make_unique<SelfcalWorker>(selfcal::SelfCalibrator(model, wall, options), std::move(camera),
                                                      inbox, sc.rate_hz);
        spdlog::info("selfcal: monitoring at {} Hz with {} (hold {} s, transition {} s, threshold {} px)", sc.rate_hz,
                     sc.models.string(), sc.hold_s, sc.transition_s, sc.drift_threshold_px);
        return worker;
    } catch (const std::invalid_argument& e) {
        refuse(e.what());
    }
}

}  // namespace mogao
