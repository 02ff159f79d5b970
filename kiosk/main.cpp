// mogao-kiosk: the appliance's boot-to-display program. This file is the one place where the
// appliance's stages are wired:
//
//   config (TOML) -> calibration (MPCDI | ideal) -> outputs (KMS | headless) + warp/blend renderer
//   navigation: scripted visitor (camera path) | tracking (camera -> TagTracker on its own thread
//               -> TagSampleQueue -> Navigator in the loop) -> view requests -> link (gRPC + mutual
//               TLS over IPv6) -> farm
//   farm frames -> latest-frame slot -> decode (TurboJPEG, last good frame kept) -> warp/blend -> outputs
//
// One thread runs everything display-side in one poll loop (kiosk/event_loop.h) over four fds:
//   signalfd  SIGINT/SIGTERM -> clean stop
//   eventfd   the link's frame callback (a gRPC thread) stored a frame in the slot
//   timerfd   display/request tick: next pose (path, or Navigator fed with the queued tag samples),
//             submit the view request, repaint when idle, log, watchdog
//   backend   DRM page-flip events (KMS only): outputs ready again, pending content presented
// See docs/kiosk.md.
//
//   mogao-kiosk --config /etc/mogao/kiosk.toml
//   mogao-kiosk --config kiosk.toml --path orbit --frames 100 --dump-content out/content
//
// Exit codes: 0 stopped (signal, --frames, --duration), 1 the appliance could not run (outputs,
// calibration, link set-up, loop failure), 2 bad command line or configuration.
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "common/projector_calibration.h"
#include "drivers/headless/headless_output.h"
#include "drivers/kms/kms_backend.h"
#include "kiosk/connecting_screen.h"
#include "kiosk/content_dump.h"
#include "kiosk/event_fd.h"
#include "kiosk/event_loop.h"
#include "kiosk/headless_recorder.h"
#include "kiosk/kiosk_config.h"
#include "kiosk/kiosk_log.h"
#include "kiosk/kiosk_stats.h"
#include "appliance/decode/last_good_frame.h"
#include "appliance/decode/latest_frame_slot.h"
#include "kiosk/screen_calibration_source.h"
#include "kiosk/pose_log.h"
#include "kiosk/screen_presenter.h"
#include "kiosk/signal_fd.h"
#include "kiosk/tag_sample_queue.h"
#include "kiosk/timer_fd.h"
#include "kiosk/tracking_thread.h"
#include "kiosk/view_script.h"
#include "common/service_notify.h"
#include "renderfarm/link/link_client.h"
#include "renderfarm/link/tls_material.h"

namespace {

using namespace mogao;

struct Flags {
    std::filesystem::path config = "/etc/mogao/kiosk.toml";
    std::string path;                 // overrides [navigation].path
    std::uint64_t frames = 0;         // stop after this many farm frames are on screen (0 = never)
    double duration_s = 0;            // stop after this long (0 = never)
    std::filesystem::path dump_dir;   // --dump-content
    int dump_every = 1;
    std::filesystem::path stats_file; // overrides [stats].file
    std::filesystem::path pose_log;   // every submitted pose, JSON lines
    bool check_only = false;
};

// Frames shown on the outputs but not yet on screen everywhere (KMS flips pending), by request id.
using PendingFrames = std::map<std::uint64_t, PresentedFrame>;
constexpr std::size_t kMaxPendingFrames = 64;

ViewRequest with_pose(ViewRequest request, const ViewerPose& pose) {
    request.pose = pose;
    return request;
}

int run(const Flags& flags, const SignalFd& signals) {
    // --- configuration -----------------------------------------------------------------------
    KioskConfig config;
    try {
        config = load_kiosk_config(flags.config);
    } catch (const KioskConfigError& e) {
        spdlog::error("{}", e.what());
        return 2;
    }
    if (!flags.path.empty()) {
        config.navigation.source = NavigationSource::path;  // --path: the scripted visitor, whatever the file says
        config.navigation.path = flags.path;
    }
    const bool tracking = config.navigation.source == NavigationSource::tracking;
    if (!flags.stats_file.empty()) config.stats.file = flags.stats_file;
    std::optional<ViewScript> script;
    TlsMaterial tls;
    try {
        if (!tracking) script.emplace(make_view_script(config));
        tls = load_tls_files(config.farm.ca, config.farm.cert, config.farm.key);
    } catch (const std::exception& e) {
        spdlog::error("{}: {}", config.source.string(), e.what());
        return 2;
    }
    if (flags.check_only) {
        spdlog::info("{}: configuration is valid", config.source.string());
        return 0;
    }

    // --- calibration -------------------------------------------------------------------------
    ScreenCalibration screen;
    std::vector<std::string> notes;
    try {
        screen = load_screen_calibration(config.calibration, config.quality.content, &notes);
    } catch (const std::exception& e) {
        spdlog::error("calibration: {}", e.what());
        return 1;
    }
    for (const auto& n : notes) spdlog::info("calibration: {}", n);
    notes.clear();

    // --- outputs -----------------------------------------------------------------------------
    std::unique_ptr<OutputBackend> backend;
    HeadlessOutputBackend* headless = nullptr;
    if (config.outputs.backend == OutputKind::headless) {
        HeadlessOptions options;
        options.outputs = config.outputs.sizes;
        if (options.outputs.empty()) {
            for (const auto& p : screen.projectors) options.outputs.push_back(p.output);
        }
        auto created = HeadlessOutputBackend::create(options);
        if (!created) {
            spdlog::error("headless outputs: {}", created.error().message);
            return 1;
        }
        headless = created->get();
        backend = std::move(created).value();
    } else {
        auto created = KmsOutputBackend::create(KmsOptions{config.outputs.device});
        if (!created) {
            spdlog::error("KMS outputs{}: {}", config.outputs.device.empty() ? "" : " on " + config.outputs.device.string(),
                          created.error().message);
            return 1;
        }
        backend = std::move(created).value();
    }
    for (const auto& o : backend->outputs()) {
        spdlog::info("output {}: {}x{}{}", o.name, o.size.width, o.size.height,
                     o.refresh_hz > 0 ? fmt::format(" @ {:.2f} Hz", o.refresh_hz) : std::string());
    }
    auto presenter_result = ScreenPresenter::create(*backend, screen, &notes);
    if (!presenter_result) {
        spdlog::error("outputs: {}", presenter_result.error().message);
        return 1;
    }
    ScreenPresenter presenter = std::move(presenter_result).value();
    for (const auto& n : notes) spdlog::warn("outputs: {}", n);

    std::optional<HeadlessRecorder> recorder;
    std::optional<ContentDump> dump;
    try {
        if (headless != nullptr && !config.outputs.png_dir.empty()) {
            recorder.emplace(*headless, config.outputs.png_dir, config.outputs.png_every);
        }
        if (!flags.dump_dir.empty()) dump.emplace(flags.dump_dir, flags.dump_every);
    } catch (const std::exception& e) {
        spdlog::error("output folders: {}", e.what());
        return 1;
    }

    KioskStats stats;
    PendingFrames pending;
    std::uint64_t frames_on_screen = 0;
    EventLoop loop;
    // After any show/repaint/on_ready: count the display round, record PNGs, and account every
    // frame that is now on screen on all outputs.
    const auto after_present = [&] {
        if (presenter.last_presents() > 0) {
            stats.display_round();
            if (recorder) {
                try {
                    recorder->write_round(stats.rounds(), presenter.current_tag());
                } catch (const std::exception& e) {
                    spdlog::warn("PNG output: {}", e.what());
                }
            }
        }
        while (const auto tag = presenter.take_completed()) {
            const auto it = pending.find(*tag);
            if (it == pending.end()) continue;  // the connecting screen (tag 0)
            PresentedFrame done = it->second;
            done.presented_ns = realtime_ns();
            stats.presented(done);
            ++frames_on_screen;
            pending.erase(pending.begin(), std::next(it));  // older ones were overtaken on some output
            if (flags.frames > 0 && frames_on_screen >= flags.frames) {
                spdlog::info("stopping: {} frames shown (--frames)", frames_on_screen);
                loop.stop();
            }
        }
    };

    // The connecting card until the first good frame.
    const Rgb8Image connecting = make_connecting_screen(config.quality.content, "FARM " + config.farm.endpoint);
    if (Status s = presenter.show(connecting, 0); !s) {
        spdlog::error("outputs: cannot show the connecting screen: {}", s.error().message);
        return 1;
    }
    after_present();

    ServiceNotifier notifier;
    notifier.ready();  // outputs are up and showing something

    // --- event sources -----------------------------------------------------------------------
    auto wake = EventFd::create();
    auto tick = TimerFd::create();
    if (!wake || !tick) {
        spdlog::error("event fds: {}", !wake ? wake.error().message : tick.error().message);
        return 1;
    }
    const auto period = std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / config.outputs.rate_hz));
    if (Status s = tick->arm(period); !s) {
        spdlog::error("display tick: {}", s.error().message);
        return 1;
    }

    // --- link --------------------------------------------------------------------------------
    LatestFrameSlot slot;
    LinkClientOptions link_options;
    link_options.endpoint = config.farm.endpoint;
    link_options.server_name = config.farm.server_name;
    link_options.tls = std::move(tls);
    std::optional<LinkClient> client;
    try {
        // Runs on the link's connection thread: hand over and wake the loop, nothing else.
        client.emplace(link_options, [&slot, &wake](LinkFrame&& frame) {
            slot.put(std::move(frame));
            if (Status s = wake->signal(); !s) spdlog::error("frame wake-up: {}", s.error().message);
        });
    } catch (const std::exception& e) {
        spdlog::error("link: {}", e.what());
        return 1;
    }
    spdlog::info("farm {}: {}x{} content, spp {}, JPEG quality {}, {}, {} Hz", config.farm.endpoint,
                 config.quality.content.width, config.quality.content.height, config.quality.spp,
                 config.quality.jpeg_quality,
                 tracking ? fmt::format("tracking '{}'", config.navigation.tracking.camera)
                          : fmt::format("path '{}' ({} poses)", config.navigation.path, script->size()),
                 config.outputs.rate_hz);

    // --- navigation input --------------------------------------------------------------------
    std::optional<PoseLog> pose_log;
    if (!flags.pose_log.empty()) {
        try {
            pose_log.emplace(flags.pose_log);
        } catch (const std::exception& e) {
            spdlog::error("--pose-log: {}", e.what());
            return 1;
        }
    }
    const ViewRequest view_template = make_view_template(config);
    std::optional<Navigator> navigator;
    TagSampleQueue samples;
    std::unique_ptr<TrackingThread> tracker;  // last: stopped before the navigator and queue go
    if (tracking) {
        try {
            navigator.emplace(config.navigation.tracking.params, start_pose(config.navigation));
            tracker = std::make_unique<TrackingThread>(config.navigation.tracking, samples);
        } catch (const std::exception& e) {
            spdlog::error("tracking: {}", e.what());
            client->stop();
            return 1;
        }
        spdlog::info("tracking: {} -> tag {} of {} mm ({}), intrinsics {}; replay end: {}", tracker->description(),
                     config.navigation.tracking.tag_id < 0 ? std::string("largest")
                                                           : std::to_string(config.navigation.tracking.tag_id),
                     config.navigation.tracking.tag_size_m * 1000.0, config.navigation.tracking.detector.family,
                     config.navigation.tracking.intrinsics_file.string(),
                     config.navigation.tracking.replay_end == ReplayEnd::stop   ? "stop"
                     : config.navigation.tracking.replay_end == ReplayEnd::loop ? "loop"
                                                                                : "idle");
    }
    std::uint64_t ticks = 0;

    LastGoodFrame last_good;
    bool connected = false;
    bool shown_since_tick = true;
    const auto start = std::chrono::steady_clock::now();
    auto last_log = start;
    int exit_code = 0;

    loop.watch(signals.fd(), [&] {
        auto sig = signals.read();
        if (!sig) {
            spdlog::error("signals: {}", sig.error().message);
            exit_code = 1;
            loop.stop();
        } else if (sig->has_value()) {
            spdlog::info("stopping: {}", **sig == SIGINT ? "SIGINT" : **sig == SIGTERM ? "SIGTERM" : "signal");
            loop.stop();
        }
    });

    loop.watch(wake->fd(), [&] {
        if (auto n = wake->drain(); !n) spdlog::error("frame wake-up: {}", n.error().message);
        std::optional<LinkFrame> frame = slot.take();
        stats.superseded(slot.replaced());
        if (!frame) return;
        const std::uint64_t on_screen = last_good.current() ? last_good.current()->request_id : 0;
        if (std::string why = last_good.accept(*frame); !why.empty()) {
            stats.rejected();
            // The first ten, then every hundredth: a farm sending garbage must not flood the journal.
            if (last_good.rejected() <= 10 || last_good.rejected() % 100 == 0) {
                spdlog::warn("frame dropped ({} so far): {}; keeping request {} on screen", last_good.rejected(), why,
                             on_screen);
            }
            return;
        }
        const ContentFrame& f = *last_good.current();
        if (dump) {
            try {
                dump->dump(f);
            } catch (const std::exception& e) {
                spdlog::warn("--dump-content: {}", e.what());
            }
        }
        pending[f.request_id] = PresentedFrame{f.request_id, f.link_frame_id, f.jpeg_bytes, f.times.request_ns,
                                               f.times.receive_ns, 0, f.decode_ms, stats.rounds() + 1};
        while (pending.size() > kMaxPendingFrames) pending.erase(pending.begin());  // an output that never completes
        if (Status s = presenter.show(f.image, f.request_id); !s) spdlog::warn("present: {}", s.error().message);
        shown_since_tick = true;
        after_present();
    });

    loop.watch(tick->fd(), [&] {
        auto expirations = tick->drain();
        if (!expirations) {
            spdlog::error("display tick: {}", expirations.error().message);
            exit_code = 1;
            loop.stop();
            return;
        }
        if (*expirations == 0) return;
        const auto now = std::chrono::steady_clock::now();
        if (flags.duration_s > 0 && std::chrono::duration<double>(now - start).count() >= flags.duration_s) {
            spdlog::info("stopping: {} s elapsed (--duration)", flags.duration_s);
            loop.stop();
            return;
        }
        // The next pose: the scripted visitor's, or the Navigator's after every pending tag sample.
        PoseLogEntry entry;
        bool replay_done = false;
        if (navigator) {
            const TagSampleQueue::Batch batch = samples.take_all();
            for (const TagSample& sample : batch.samples) navigator->observe(sample);
            entry.tracking_source = true;
            entry.samples = batch.samples.size();
            replay_done = batch.closed && config.navigation.tracking.replay_end == ReplayEnd::stop;
        }
        entry.time_ns = monotonic_ns();
        const ViewRequest request =
            navigator ? with_pose(view_template, navigator->advance(entry.time_ns)) : script->next();
        if (navigator) {
            entry.tracking = navigator->tracking();
            entry.velocity = navigator->velocity();
        }
        std::string why;
        entry.request_id = client->submit(request, &why);
        if (entry.request_id == 0) spdlog::error("view request refused: {}", why);
        entry.tick = ++ticks;
        entry.pose = request.pose;
        if (pose_log) {
            try {
                pose_log->write(entry);
            } catch (const std::exception& e) {
                spdlog::error("--pose-log: {}; no more poses are logged", e.what());
                pose_log.reset();
            }
        }
        if (replay_done) {
            spdlog::info("stopping: the tracking replay ended (replay_end = \"stop\")");
            loop.stop();
        }
        const LinkClientStats link = client->stats();
        if (link.connected != connected) {
            connected = link.connected;
            const std::uint64_t last = last_good.current() ? last_good.current()->request_id : 0;
            spdlog::info("farm {} {}; showing {}", config.farm.endpoint, connected ? "connected" : "disconnected",
                         last == 0 ? std::string("the connecting screen") : fmt::format("request {}", last));
            stats.event(realtime_ns(), connected ? "connected" : "disconnected", last);
        }
        if (!shown_since_tick) {
            // Nothing new this tick: show the current frame again (headless PNGs keep coming, a
            // KMS output is refreshed); outputs with a flip pending are left alone.
            if (Status s = presenter.repaint(); !s) spdlog::warn("repaint: {}", s.error().message);
            after_present();
        }
        shown_since_tick = false;
        if (std::chrono::duration<double>(now - last_log).count() >= config.stats.log_period_s) {
            spdlog::info("stats: {} link_sessions={} link_connected={}", stats.log_line(), link.sessions_opened,
                         link.connected);
            last_log = now;
        }
        notifier.watchdog();
    });

    loop.watch(backend->event_fd(), [&] {
        auto ready = backend->dispatch_events();
        if (!ready) {
            spdlog::error("output events: {}", ready.error().message);
            exit_code = 1;
            loop.stop();
            return;
        }
        if (Status s = presenter.on_ready(*ready); !s) spdlog::warn("present: {}", s.error().message);
        after_present();
    });

    if (Status s = loop.run(); !s) {
        spdlog::error("event loop: {}", s.error().message);
        exit_code = 1;
    }

    // --- shutdown: no more frames, then the record of the run ---------------------------------
    notifier.stopping();
    if (tracker) tracker->stop();
    client->stop();
    if (pose_log) {
        try {
            pose_log->close();
        } catch (const std::exception& e) {
            spdlog::error("--pose-log: {}", e.what());
            if (exit_code == 0) exit_code = 1;
        }
    }
    nlohmann::json navigation_stats = {{"source", tracking ? "tracking" : "path"}, {"ticks", ticks}};
    if (tracker) {
        const TrackingCounters c = tracker->counters();
        navigation_stats.update({{"camera", tracker->description()},
                                 {"frames_tracked", c.frames},
                                 {"frames_skipped", c.skipped},
                                 {"tag_visible", c.visible},
                                 {"ambiguous", c.ambiguous},
                                 {"frame_errors", c.frame_errors},
                                 {"camera_timeouts", c.timeouts},
                                 {"camera_reopens", c.reopens},
                                 {"replay_ended", c.ended},
                                 {"samples_queued", samples.pushed()},
                                 {"samples_dropped", samples.dropped()},
                                 {"samples_rejected_by_gate", navigator->rejected_samples()},
                                 {"final_pose", {{"eye", {navigator->pose().eye.x(), navigator->pose().eye.y(),
                                                          navigator->pose().eye.z()}},
                                                 {"yaw_deg", navigator->pose().yaw_deg}}}});
        spdlog::info("tracking: {} frames ({} skipped behind newer ones), tag visible in {}, {} rejected by the "
                     "flip gate, {} samples dropped",
                     c.frames, c.skipped, c.visible, navigator->rejected_samples(), samples.dropped());
    }
    const LinkClientStats link = client->stats();
    spdlog::info("stats: {} link_sessions={}", stats.log_line(), link.sessions_opened);
    if (recorder && config.outputs.composite) {
        const auto file = recorder->dir() / "screen-composite.png";
        try {
            recorder->write_composite(screen, presenter.projector_of(), file);
            spdlog::info("composited screen: {}", file.string());
        } catch (const std::exception& e) {
            spdlog::warn("composited screen: {}", e.what());
        }
    }
    if (!config.stats.file.empty()) {
        const nlohmann::json extra = {
            {"endpoint", config.farm.endpoint},
            {"content", {config.quality.content.width, config.quality.content.height}},
            {"jpeg_quality", config.quality.jpeg_quality},
            {"navigation", navigation_stats},
            {"link", {{"sessions_opened", link.sessions_opened},
                      {"attempts_failed", link.attempts_failed},
                      {"requests_submitted", link.requests_submitted},
                      {"requests_sent", link.requests_sent},
                      {"requests_coalesced", link.requests_coalesced},
                      {"frames_received", link.frames_received},
                      {"frames_discarded", link.frames_discarded},
                      {"bytes_received", link.bytes_received}}},
            {"exit_code", exit_code}};
        try {
            stats.write_json(config.stats.file, extra);
            spdlog::info("statistics: {}", config.stats.file.string());
        } catch (const std::exception& e) {
            spdlog::error("statistics: {}", e.what());
            if (exit_code == 0) exit_code = 1;
        }
    }
    return exit_code;
}

}  // namespace

int main(int argc, char** argv) {
    mogao::setup_kiosk_logging();
    // Before any thread exists (gRPC, llvmpipe): every thread inherits SIGINT/SIGTERM blocked and
    // they reach the loop through the signalfd only.
    auto signals = mogao::SignalFd::create({SIGINT, SIGTERM});
    if (!signals) {
        spdlog::error("signals: {}", signals.error().message);
        return 1;
    }
    CLI::App app{"mogao-kiosk: the appliance's projector outputs, fed by the render farm (docs/kiosk.md)"};
    Flags flags;
    app.add_option("--config", flags.config, "Configuration file (TOML)")->check(CLI::ExistingFile);
    app.add_option("--path", flags.path,
                   "Scripted visitor: walk | orbit | a JSON path file (overrides [navigation].path and .source)");
    app.add_option("--frames", flags.frames, "Stop after this many farm frames are on screen")->check(CLI::Range(1, 100000000));
    app.add_option("--duration", flags.duration_s, "Stop after this many seconds")->check(CLI::Range(0.001, 1e9));
    app.add_option("--dump-content", flags.dump_dir, "Write decoded content frames (PPM + pose JSON) here");
    app.add_option("--dump-every", flags.dump_every, "With --dump-content: every k-th frame")->check(CLI::Range(1, 1000000));
    app.add_option("--stats", flags.stats_file, "Statistics JSON written at exit (overrides [stats].file)");
    app.add_option("--pose-log", flags.pose_log, "Write every submitted pose here (JSON lines, one per display tick)");
    app.add_flag("--check-config", flags.check_only, "Validate the configuration (and TLS files, path) and exit");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);
        return code == 0 ? 0 : 2;
    }
    try {
        return run(flags, *signals);
    } catch (const std::exception& e) {
        spdlog::critical("{}", e.what());
        return 1;
    }
}
