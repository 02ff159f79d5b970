// SPDX-License-Identifier: Apache-2.0
#include "kiosk/loop/kiosk_setup.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "appliance/autocal/model_store.h"
#include "drivers/headless/headless_output.h"
#include "drivers/kms/kms_backend.h"
#include "kiosk/live_calibration/screen_calibration_source.h"

namespace mogao {

std::unique_ptr<OutputBackend> open_output_backend(const OutputsConfig& outputs, const ScreenCalibration& screen,
                                                   HeadlessOutputBackend** headless) {
    if (outputs.backend == OutputKind::headless) {
        HeadlessOptions options;
        options.outputs = outputs.sizes;
        if (options.outputs.empty()) {
            for (const auto& p : screen.projectors) options.outputs.push_back(p.output);
        }
        auto created = HeadlessOutputBackend::create(options);
        if (!created) throw KioskSetupError(1, "headless outputs: " + created.error().message);
        *headless = created->get();
        return std::move(created).value();
    }
    auto created = KmsOutputBackend::create(KmsOptions{outputs.device});
    if (!created) {
        throw KioskSetupError(
            1, fmt::format("KMS outputs{}: {}", outputs.device.empty() ? "" : " on " + outputs.device.string(),
                           created.error().message));
    }
    return std::move(created).value();
}

KioskSetup load_setup(const std::filesystem::path& file, const std::string& path,
                      const std::filesystem::path& stats_file, bool fall_back) {
    KioskSetup setup;
    try {
        setup.config = load_kiosk_config(file);
        if (fall_back) keep_last_loaded(file);
    } catch (const KioskConfigError& e) {
        const std::filesystem::path copy = last_loaded_path(file);
        std::error_code ec;
        if (!fall_back || !std::filesystem::exists(copy, ec)) throw KioskSetupError(2, e.what());
        try {
            setup.config = load_kiosk_config(copy);  // the same folder: relative paths resolve alike
        } catch (const KioskConfigError& again) {
            throw KioskSetupError(2, fmt::format("{} (its last good copy is bad too: {})", e.what(), again.what()));
        }
        const std::string message = fmt::format("{}; running on its last good copy {}", e.what(), copy.string());
        spdlog::error("configuration: {}", message);
        setup.fallbacks.push_back({"CONFIG ERROR - LAST GOOD IN USE", message});
    }
    KioskConfig& config = setup.config;
    if (!path.empty()) {
        config.navigation.source = NavigationSource::path;  // --path: the scripted visitor, whatever the file says
        config.navigation.path = path;
    }
    if (!stats_file.empty()) config.stats.file = stats_file;
    try {
        if (config.navigation.source != NavigationSource::tracking) setup.script.emplace(scripted_visitor(config));
        setup.tls = load_tls_files(config.farm.ca, config.farm.cert, config.farm.key);
    } catch (const std::exception& e) {
        throw KioskSetupError(2, fmt::format("{}: {}", config.source.string(), e.what()));
    }
    return setup;
}

ScreenCalibration load_calibration(const KioskConfig& config, std::vector<StartFallback>* fallbacks) {
    std::vector<std::string> notes;
    ScreenCalibration screen;
    const std::filesystem::path& mpcdi = config.calibration.mpcdi;
    try {
        screen = load_screen_calibration(config.calibration, config.quality.content, &notes);
        if (fallbacks != nullptr && !mpcdi.empty()) keep_last_loaded(mpcdi);
    } catch (const std::exception& e) {
        std::error_code ec;
        if (fallbacks == nullptr || mpcdi.empty() || !std::filesystem::exists(last_loaded_path(mpcdi), ec)) {
            throw KioskSetupError(1, fmt::format("calibration: {}", e.what()));
        }
        CalibrationConfig copy = config.calibration;
        copy.mpcdi = last_loaded_path(mpcdi);
        try {
            screen = load_screen_calibration(copy, config.quality.content, &notes);
        } catch (const std::exception& again) {
            throw KioskSetupError(
                1, fmt::format("calibration: {} (its last good copy is bad too: {})", e.what(), again.what()));
        }
        const std::string message = fmt::format("{}; running on its last good copy {}", e.what(), copy.mpcdi.string());
        spdlog::error("calibration: {}", message);
        fallbacks->push_back({"CALIBRATION ERROR - LAST GOOD IN USE", message});
    }
    for (const auto& n : notes) spdlog::info("calibration: {}", n);
    return screen;
}

std::unique_ptr<CalibrationInbox> open_calibration_inbox() {
    auto inbox = CalibrationInbox::create();
    if (!inbox) throw KioskSetupError(1, "event fds: " + inbox.error().message);
    return std::move(inbox).value();
}

std::unique_ptr<CalibrationWatcher> watch_calibration(const KioskConfig& config, CalibrationInbox& inbox) {
    if (config.calibration.mpcdi.empty() || !config.calibration.watch) return nullptr;
    const CalibrationConfig calibration = config.calibration;
    const ImageSize content = config.quality.content;
    auto watcher = CalibrationWatcher::create(
        calibration.mpcdi,
        [calibration, content](std::vector<std::string>* notes) {
            return load_screen_calibration(calibration, content, notes);
        },
        inbox);
    if (!watcher) throw KioskSetupError(1, "calibration: watching for changes: " + watcher.error().message);
    spdlog::info("calibration: {} is swapped in when it changes", calibration.mpcdi.string());
    return std::move(watcher).value();
}

KioskDisplay open_display(const KioskConfig& config, ScreenCalibration screen) {
    HeadlessOutputBackend* headless = nullptr;
    std::unique_ptr<OutputBackend> backend = open_output_backend(config.outputs, screen, &headless);
    for (const auto& o : backend->outputs()) {
        spdlog::info("output {}: {}x{}{}", o.name, o.size.width, o.size.height,
                     o.refresh_hz > 0 ? fmt::format(" @ {:.2f} Hz", o.refresh_hz) : std::string());
    }
    std::vector<std::string> notes;
    auto display = KioskDisplay::create(std::move(backend), std::move(screen), &notes);
    if (!display) throw KioskSetupError(1, "outputs: " + display.error().message);
    for (const auto& n : notes) spdlog::warn("outputs: {}", n);
    if (!config.calibration.mpcdi.empty() && config.calibration.indirect_light) {
        // The models file beside the MPCDI (written with it) gives the screen's reflectance for its own light.
        display->take_off_indirect_light(
            [models = autocal::models_path_for(config.calibration.mpcdi)](const ScreenCalibration& s) {
                std::string note;
                std::optional<FrameIndirectLight> light = load_frame_indirect_light(models, s, &note);
                spdlog::info("calibration: {}", note);
                return light;
            });
    }
    display->stats() = KioskStats(KioskStats::kDefaultWindow, static_cast<std::size_t>(config.stats.frames_kept));
    if (!config.stats.frame_log.empty()) {
        try {
            display->stats().open_frame_log(config.stats.frame_log);
        } catch (const std::exception& e) {
            throw KioskSetupError(1, fmt::format("[stats] frame_log: {}", e.what()));
        }
        spdlog::info("frame log: every presented frame is appended to {}", config.stats.frame_log.string());
    }
    if (headless != nullptr && !config.outputs.png_dir.empty()) {
        try {
            display->record_to(HeadlessRecorder(*headless, config.outputs.png_dir, config.outputs.png_every));
        } catch (const std::exception& e) {
            throw KioskSetupError(1, fmt::format("output folders: {}", e.what()));
        }
    }
    return std::move(display).value();
}

std::optional<ContentDump> open_content_dump(const std::filesystem::path& dir, int every) {
    if (dir.empty()) return std::nullopt;
    try {
        return ContentDump(dir, every);
    } catch (const std::exception& e) {
        throw KioskSetupError(1, fmt::format("output folders: {}", e.what()));
    }
}

std::unique_ptr<FrameInbox> open_inbox() {
    auto inbox = FrameInbox::create();
    if (!inbox) throw KioskSetupError(1, "event fds: " + inbox.error().message);
    return std::move(inbox).value();
}

std::unique_ptr<LinkClient> open_link(const KioskConfig& config, TlsMaterial tls, FrameInbox& inbox,
                                      const std::optional<ViewScript>& script) {
    LinkClientOptions options;
    options.endpoint = config.farm.endpoint;
    options.server_name = config.farm.server_name;
    options.tls = std::move(tls);
    // Rotation without a restart: the client re-reads these when they change (docs/link.md).
    options.tls_files = {config.farm.ca, config.farm.cert, config.farm.key};
    std::unique_ptr<LinkClient> client;
    try {
        // Runs on the link's connection thread: hand over and wake the loop, nothing else.
        client = std::make_unique<LinkClient>(options, [&inbox](LinkFrame&& frame) { inbox.put(std::move(frame)); });
    } catch (const std::exception& e) {
        throw KioskSetupError(1, fmt::format("link: {}", e.what()));
    }
    spdlog::info("farm {}: {}x{} content, spp {}, JPEG quality {}, {}, {} Hz", config.farm.endpoint,
                 config.quality.content.width, config.quality.content.height, config.quality.spp,
                 config.quality.jpeg_quality,
                 script ? fmt::format("path '{}' ({} poses)", config.navigation.path, script->size())
                        : fmt::format("tracking '{}'", config.navigation.tracking.camera),
                 config.outputs.rate_hz);
    return client;
}

std::optional<PoseLog> open_pose_log(const std::filesystem::path& file) {
    if (file.empty()) return std::nullopt;
    try {
        return PoseLog(file);
    } catch (const std::exception& e) {
        throw KioskSetupError(1, fmt::format("--pose-log: {}", e.what()));
    }
}

ViewRequest view_template(const KioskConfig& config) { return make_view_template(config.screen, config.quality); }

ViewScript scripted_visitor(const KioskConfig& config) {
    return make_view_script(config.navigation, view_template(config));
}

std::unique_ptr<KioskNavigation> start_navigation(const KioskConfig& config, std::optional<ViewScript> script) {
    if (config.navigation.source != NavigationSource::tracking)
        return std::make_unique<KioskNavigation>(std::move(*script));
    try {
        return std::make_unique<KioskNavigation>(config.navigation, view_template(config));
    } catch (const std::exception& e) {
        throw KioskSetupError(1, fmt::format("tracking: {}", e.what()));
    }
}

}  // namespace mogao
