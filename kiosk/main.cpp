// SPDX-License-Identifier: Apache-2.0
// mogao-kiosk: the appliance's boot-to-display program. This file is the one place where the
// appliance's stages are wired, in pipeline order (docs/kiosk.md):
//
//   config (TOML) -> calibration (MPCDI | ideal) -> outputs (KMS | headless, connecting screen)
//   -> calibration swap (watcher of the MPCDI; self-recalibration worker when [selfcal] is on)
//   -> link (gRPC + mutual TLS over IPv6; frames into the FrameInbox) -> navigation (scripted
//   visitor | tracking thread -> Navigator) -> the Kiosk's poll loop (kiosk/loop/kiosk.h: signals, frames,
//   display tick, page flips) -> clean stop and statistics
//
//   mogao-kiosk --config /etc/mogao/kiosk.toml
//   mogao-kiosk --config kiosk.toml --path orbit --frames 100 --dump-content out/content
//   mogao-kiosk --print-config 'farm.endpoint="[::1]:7443"' > kiosk.toml   # the example, overridden
//
// Exit codes: 0 stopped (signal, --frames, --duration-s, end of a tracking replay), 1 the appliance
// could not run (outputs, calibration, link set-up, loop failure), 2 bad command line or configuration.
// A bad configuration or MPCDI file with a last good copy (kiosk/config/last_loaded.h) runs on the copy
// and says so on the wall and in the status file instead of exiting.
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "common/program_cli.h"
#include "common/service_notify.h"
#include "common/signal_fd.h"
#include "kiosk/config/config_overrides.h"
#include "kiosk/display/service_screen.h"
#include "kiosk/live_calibration/selfcal_setup.h"
#include "kiosk/loop/kiosk.h"
#include "kiosk/loop/kiosk_setup.h"
#include "kiosk/stats/kiosk_log.h"

namespace {

using namespace mogao;

struct Flags {
    std::filesystem::path config = "/etc/mogao/kiosk.toml";
    std::string path;                // overrides [navigation].path
    std::uint64_t frames = 0;        // stop after this many farm frames are on screen (0 = never)
    double duration_s = 0;           // stop after this long (0 = never)
    std::filesystem::path dump_dir;  // --dump-content
    int dump_every = 1;
    std::filesystem::path stats_file;  // overrides [stats].file
    std::filesystem::path pose_log;    // every submitted pose, JSON lines
    bool check_only = false;
    std::filesystem::path service_config;  // [outputs] of the service card (empty: built-in defaults)
};

int run(const Flags& flags, const SignalFd& signals) {
    // --check-config judges the file itself: no falling back to its last good copy.
    KioskSetup setup = load_setup(flags.config, flags.path, flags.stats_file, !flags.check_only);
    const KioskConfig& config = setup.config;
    if (flags.check_only) {
        spdlog::info("{}: configuration is valid", config.source.string());
        return 0;
    }
    std::vector<StartFallback> fallbacks = setup.fallbacks;
    KioskDisplay display = open_display(config, load_calibration(config, &fallbacks));
    std::optional<ContentDump> dump = open_content_dump(flags.dump_dir, flags.dump_every);
    if (Status s = display.show_connecting_screen(config.quality.content, config.farm.endpoint); !s) {
        throw KioskSetupError(1, "outputs: cannot show the connecting screen: " + s.error().message);
    }
    ServiceNotifier notifier;
    notifier.ready();  // outputs are up and showing something

    const std::unique_ptr<CalibrationInbox> calibration = open_calibration_inbox();
    const std::unique_ptr<CalibrationWatcher> watcher = watch_calibration(config, *calibration);
    const std::unique_ptr<SelfcalWorker> selfcal = start_selfcal(
        config.selfcal, config.calibration.mpcdi, display.calibration(), *calibration, built_in_simulated_camera());
    const std::unique_ptr<FrameInbox> inbox = open_inbox();
    const std::unique_ptr<LinkClient> link = open_link(config, std::move(setup.tls), *inbox, setup.script);
    std::optional<PoseLog> pose_log = open_pose_log(flags.pose_log);
    const std::unique_ptr<KioskNavigation> navigation = start_navigation(config, std::move(setup.script));

    KioskParts parts{display, *inbox, link_of(*link), *navigation, signals, notifier, calibration.get()};
    parts.selfcal = selfcal.get();
    KioskRunOptions options{flags.frames, flags.duration_s, std::move(dump), std::move(pose_log)};
    options.fallbacks = std::move(fallbacks);
    options.flip_timeout = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(config.outputs.flip_timeout_s));
    Kiosk kiosk(config, std::move(parts), std::move(options));
    return kiosk.run();
}

// The show cannot start (no configuration or calibration, nor a last good copy): the service card
// says so on the wall until the configuration loads again (kiosk/display/service_screen.h). Other errors,
// and outputs that cannot show the card either, keep their exit code.
int show_service_card(const Flags& flags, const KioskSetupError& error, const SignalFd& signals) {
    const bool config = error.exit_code == 2;
    if (!config && !std::string_view(error.what()).starts_with("calibration:")) return error.exit_code;
    ServiceScreenOptions options;
    options.config = flags.config;
    options.reason = error.what();
    options.duration_s = flags.duration_s;
    try {
        options.outputs = service_outputs(flags.service_config);
    } catch (const std::exception& e) {
        spdlog::error("--service-config: {}", e.what());
        return error.exit_code;
    }
    return run_service_screen(options, signals).value_or(error.exit_code);
}

// --print-config [KEY=VALUE | @FILE]...: kiosk.example.toml with the overrides applied, on stdout.
int print_config(std::vector<std::string> overrides) {
    if (overrides == std::vector<std::string>{""}) overrides.clear();  // CLI11's value of a bare --print-config
    try {
        std::cout << apply_config_overrides(kiosk_example_toml(), expand_override_files(overrides));
        return 0;
    } catch (const KioskConfigError& e) {
        spdlog::error("--print-config: {}", e.what());
        return 2;
    }
}

}  // namespace

int main(int argc, char** argv) {
    // First, before any thread exists (gRPC, llvmpipe, TBB): every thread inherits SIGINT/SIGTERM
    // blocked and they reach the loop through the signalfd only (SIGUSR2: the status panel on the
    // wall). They stay blocked until the process has exited (signal_fd.h: keep_blocked), so a stop
    // that arrives while the kiosk is already on its way out still ends it with its own exit code.
    auto signals = mogao::SignalFd::create({SIGINT, SIGTERM, SIGUSR2}, mogao::SignalFd::OnDestroy::keep_blocked);
    mogao::setup_kiosk_logging();
    if (!signals) {
        spdlog::error("signals: {}", signals.error().message);
        return 1;
    }
    CLI::App app{"mogao-kiosk: the appliance's projector outputs, fed by the render farm (docs/kiosk.md)"};
    mogao::cli::prepare(app, "mogao-kiosk");
    Flags flags;
    std::vector<std::string> overrides;
    // Not CLI::ExistingFile: a missing file (an unmounted configuration partition) is reported on the
    // wall by the service card, not by an exit into a restart loop (kiosk/display/service_screen.h).
    app.add_option("--config", flags.config, "Configuration file (TOML)");
    app.add_option("--service-config", flags.service_config,
                   "Configuration whose [outputs] show the service card when --config and its last good copy "
                   "cannot be loaded (default: built-in, KMS)");
    app.add_option("--path", flags.path, mogao::cli::kPathHelp);
    app.add_option("--frames", flags.frames, "Stop after this many farm frames are on screen")
        ->check(CLI::Range(1, 100000000));
    mogao::cli::add_duration_flag(app, flags.duration_s);
    app.add_option("--dump-content", flags.dump_dir, "Write decoded content frames (PPM + pose JSON) here");
    app.add_option("--dump-every", flags.dump_every, "With --dump-content: every k-th frame")
        ->check(CLI::Range(1, 1000000));
    app.add_option("--stats", flags.stats_file, "Statistics JSON written at exit (overrides [stats].file)");
    app.add_option("--pose-log", flags.pose_log, "Write every submitted pose here (JSON lines, one per display tick)");
    app.add_flag("--check-config", flags.check_only, "Validate the configuration (and TLS files, path) and exit");
    auto* print = app.add_option("--print-config", overrides,
                                 "Print kiosk.example.toml with overrides: section.key=VALUE (TOML value; empty: "
                                 "commented out) or @FILE of such lines, then exit")
                      ->expected(0, 1 << 20);
    if (auto status = mogao::cli::parse(app, argc, argv)) return *status;
    if (print->count() > 0) return print_config(overrides);
    try {
        return run(flags, *signals);
    } catch (const KioskSetupError& e) {
        spdlog::error("{}", e.what());
        return flags.check_only ? e.exit_code : show_service_card(flags, e, *signals);
    } catch (const std::exception& e) {
        spdlog::critical("{}", e.what());
        return 1;
    }
}
