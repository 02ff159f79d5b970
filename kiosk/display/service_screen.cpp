// SPDX-License-Identifier: Apache-2.0
#include "kiosk/display/service_screen.h"

#include <poll.h>

#include <algorithm>
#include <csignal>

#include <spdlog/spdlog.h>

#include "appliance/warp/ideal_calibration.h"
#include "common/service_notify.h"
#include "drivers/headless/headless_output.h"
#include "kiosk/config/config_overrides.h"
#include "kiosk/display/connecting_screen.h"
#include "kiosk/loop/kiosk_setup.h"

namespace mogao {
namespace {

constexpr ImageSize kCardSize{1280, 720};
constexpr ImageSize kHeadlessDefault{1024, 768};  // headless without [outputs].sizes

// One projector per output, each showing the whole card on its output alone.
ScreenCalibration card_calibration(const std::vector<OutputInfo>& outputs) {
    ScreenCalibration screen;
    screen.content = kCardSize;
    for (std::size_t i = 0; i < outputs.size(); ++i) {
        IdealCalibrationParams params;
        params.projectors = 1;
        params.overlap = 0.0;
        params.output = outputs[i].size;
        params.content = kCardSize;
        ProjectorCalibration p = make_ideal_calibration(params).projectors.at(0);
        p.id = "service-" + std::to_string(i);
        screen.projectors.push_back(std::move(p));
    }
    return screen;
}

// The card's detail line: upper case (the font's), and short enough to read across a projector.
std::string detail_line(const std::filesystem::path& config, const std::string& reason) {
    std::string text = reason.empty() ? config.string() : reason;
    if (text.size() > 150) text = text.substr(0, 147) + "...";
    return text;
}

bool config_loads(const std::filesystem::path& file) {
    try {
        (void)load_kiosk_config(file);
        return true;
    } catch (const std::exception&) {
        return false;
    }
}

}  // namespace

OutputsConfig service_outputs(const std::filesystem::path& file) {
    if (file.empty()) return parse_outputs_config(kiosk_example_toml(), "built-in kiosk.example.toml");
    return load_outputs_config(file);
}

std::optional<int> run_service_screen(const ServiceScreenOptions& options, const SignalFd& signals) {
    spdlog::critical("service card on every output: {}", options.reason);
    HeadlessOutputBackend* headless = nullptr;
    ScreenCalibration sizes;  // headless without sizes: one default-sized output
    sizes.projectors.resize(1);
    sizes.projectors[0].output = kHeadlessDefault;
    std::unique_ptr<OutputBackend> backend;
    try {
        backend = open_output_backend(options.outputs, sizes, &headless);
    } catch (const KioskSetupError& e) {
        spdlog::error("service card: {}", e.what());
        return std::nullopt;
    }
    ScreenCalibration screen = card_calibration(backend->outputs());
    std::vector<std::string> notes;
    auto display = KioskDisplay::create(std::move(backend), std::move(screen), &notes);
    if (!display) {
        spdlog::error("service card: outputs: {}", display.error().message);
        return std::nullopt;
    }
    if (headless != nullptr && !options.outputs.png_dir.empty()) {
        display->record_to(HeadlessRecorder(*headless, options.outputs.png_dir, 1));
    }
    if (Status s = display->show_card(
            make_title_card(kCardSize, "SERVICE NEEDED", detail_line(options.config, options.reason)));
        !s) {
        spdlog::error("service card: {}", s.error().message);
        return std::nullopt;
    }
    ServiceNotifier notifier;
    notifier.ready();
    const auto start = std::chrono::steady_clock::now();
    auto next_try = start + options.retry;
    for (;;) {
        pollfd fds[] = {{signals.fd(), POLLIN, 0}, {display->event_fd(), POLLIN, 0}};
        (void)poll(fds, 2, 250);
        notifier.watchdog();
        if (fds[0].revents & POLLIN) {
            auto sig = signals.read();
            if (sig && sig->has_value() && (**sig == SIGTERM || **sig == SIGINT)) break;
        }
        if (fds[1].revents & POLLIN) (void)display->on_flip();
        const auto now = std::chrono::steady_clock::now();
        if (options.duration_s > 0 && now - start >= std::chrono::duration<double>(options.duration_s)) break;
        if (now >= next_try) {
            next_try = now + options.retry;
            if (config_loads(options.config)) {
                spdlog::info("{}: loads again; exiting for systemd to start the show", options.config.string());
                notifier.stopping();
                return 1;
            }
        }
    }
    notifier.stopping();
    return 0;
}

}  // namespace mogao
