// SPDX-License-Identifier: Apache-2.0
#include "kiosk/loop/kiosk.h"

#include <poll.h>

#include <csignal>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "common/program_cli.h"
#include "kiosk/display/on_wall_status.h"
#include "kiosk/loop/kiosk_setup.h"
#include "kiosk/stats/kiosk_metrics.h"

namespace mogao {

namespace {

TimerFd armed_tick(double rate_hz) {
    auto tick = TimerFd::create();
    if (!tick) throw KioskSetupError(1, "display tick: " + tick.error().message);
    const auto period = std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / rate_hz));
    if (Status s = tick->arm(period); !s) throw KioskSetupError(1, "display tick: " + s.error().message);
    return std::move(tick).value();
}

const char* signal_name(int sig) { return sig == SIGINT ? "SIGINT" : sig == SIGTERM ? "SIGTERM" : "signal"; }

bool file_exists(const std::filesystem::path& p) {
    std::error_code ec;
    return !p.empty() && std::filesystem::exists(p, ec);
}

std::string showing(const ContentFrame* current) {
    const std::uint64_t last = current ? current->request_id : 0;
    return last == 0 ? std::string("the connecting screen") : fmt::format("request {}", last);
}

}  // namespace

KioskLink link_of(LinkClient& client) {
    return {[&client](ViewRequest request, std::string* why) { return client.submit(std::move(request), why); },
            [&client] { return client.stats(); }, [&client] { client.stop(); }};
}

Kiosk::Kiosk(const KioskConfig& config, KioskParts parts, KioskRunOptions options)
    : config_(config),
      parts_(std::move(parts)),
      options_(std::move(options)),
      tick_(armed_tick(config.outputs.rate_hz)),
      start_(std::chrono::steady_clock::now()),
      last_log_(start_),
      repaint_pacer_(config.outputs.late_warp_duty),
      last_status_(start_),
      last_frame_at_(start_) {
    map_large_blocks();  // large buffers map instead of growing the heap (common/memory_release.h)
    if (config.guard_deg > 0) {
        auto guarded = guard_band(config.screen, config.quality.content, config.guard_deg);
        if (!guarded) throw KioskSetupError(1, "[screen].guard_deg: " + guarded.error().message);
        if (guarded->guard_px > 0) guard_.emplace(std::move(guarded).value());
    }
    loop_.watch(parts_.signals.fd(), [this] { on_signal(); });
    loop_.watch(parts_.inbox.fd(), [this] { on_frame(); });
    loop_.watch(tick_.fd(), [this] { on_tick(); });
    loop_.watch(parts_.display.event_fd(), [this] { on_flip(); });  // -1 headless: ignored
    if (parts_.calibration != nullptr) loop_.watch(parts_.calibration->fd(), [this] { on_calibration(); });
    calibration_.source = config.calibration.mpcdi.empty() ? std::string("ideal") : config.calibration.mpcdi.string();
    calibration_.loaded_ns = realtime_ns();
    write_status("connecting");
    // Every output drawn is progress: one round of several outputs may outlast WatchdogSec on a
    // software rasteriser while the loop is healthy (screen_presenter.h).
    parts_.display.on_output_presented([this] { parts_.notifier.watchdog(); });
}

int Kiosk::run() {
    if (Status s = loop_.run(); !s) {
        spdlog::error("event loop: {}", s.error().message);
        exit_code_ = 1;
    }
    return finish();
}

void Kiosk::fail(const char* what, const std::string& message) {
    spdlog::error("{}: {}", what, message);
    exit_code_ = 1;
    loop_.stop();
}

void Kiosk::note_error(std::string what) {
    last_error_ = std::move(what);
    last_error_ns_ = realtime_ns();
}

void Kiosk::on_signal() {
    auto sig = parts_.signals.read();
    if (!sig) return fail("signals", sig.error().message);
    if (!sig->has_value()) return;
    if (**sig == SIGUSR2) {
        if (config_.status.on_wall != OnWall::on_demand) {
            spdlog::info("SIGUSR2: the status panel is {} ([status].on_wall)",
                         config_.status.on_wall == OnWall::off ? "off" : "always shown");
            return;
        }
        panel_toggled_ = !panel_toggled_;
        spdlog::info("SIGUSR2: status panel {} on the wall", panel_toggled_ ? "shown" : "taken off");
        update_wall(std::chrono::steady_clock::now());
        return;
    }
    spdlog::info("stopping: {}", signal_name(**sig));
    loop_.stop();
}

void Kiosk::on_frame() {
    DecodeWorker::Taken taken = parts_.inbox.take();  // decoded on the inbox's worker thread
    note_rejections(taken.rejections);
    // A frame held back during a pattern pair and replaced before it was shown is superseded too.
    if (taken.frame && frame_held_back_) ++held_back_replaced_;
    parts_.display.stats().superseded(parts_.inbox.replaced() + held_back_replaced_);
    if (!taken.frame) return;  // nothing new: the last good frame stays
    current_ = std::move(taken.frame);
    const ContentFrame& f = *current_;
    if (options_.dump) {
        try {
            options_.dump->dump(f);
        } catch (const std::exception& e) {
            spdlog::warn("--dump-content: {}", e.what());
            note_error(std::string("content dump: ") + e.what());
        }
    }
    last_frame_at_ = std::chrono::steady_clock::now();
    wall_lines_ = wall_lines(last_frame_at_);
    if (pattern_base_) {
        frame_held_back_ = true;  // shown, with its own late warp, when the pattern pair is over
        return;
    }
    (void)update_late_warp();  // this frame's shift for the yaw turned since its request
    show_current();
}

void Kiosk::show_current() {
    const ContentFrame& f = *current_;
    const std::uint64_t rounds = parts_.display.stats().rounds();
    const auto start = std::chrono::steady_clock::now();
    if (wall_lines_.empty()) {
        parts_.display.show(f);
    } else {
        ContentFrame marked = f;  // the copy only while something is on the wall
        marked.image = with_wall_lines(f.image);
        parts_.display.show(marked);
    }
    if (parts_.display.stats().rounds() != rounds) repaint_pacer_.drew(start, std::chrono::steady_clock::now());
    shown_since_tick_ = true;
    check_frames_shown();
}

void Kiosk::update_pattern_overlay() {
    if (parts_.selfcal == nullptr || !current_) return;
    const std::optional<SelfcalWorker::Overlay> overlay = parts_.selfcal->overlay();
    if (!overlay) {
        if (!pattern_base_) return;
        pattern_base_.reset();
        overlay_id_ = 0;
        (void)update_late_warp();  // the shift was held with the frame
        if (frame_held_back_) {
            frame_held_back_ = false;
            show_current();
        } else {
            parts_.display.refresh_content(wall_lines_.empty() ? current_->image : with_wall_lines(current_->image));
        }
        return;
    }
    if (overlay->id != overlay_id_) {
        if (!pattern_base_) pattern_base_ = wall_lines_.empty() ? current_->image : with_wall_lines(current_->image);
        overlay_id_ = overlay->id;
        overlay_told_ = false;
        overlay_image_ = with_pattern(*pattern_base_, overlay->signed_pattern);
        parts_.display.refresh_content(overlay_image_);
        return;  // told once every output has completed it (a later tick or flip event)
    }
    tell_overlay_shown();
}

void Kiosk::tell_overlay_shown() {
    if (overlay_id_ == 0 || overlay_told_ || !parts_.display.all_outputs_ready()) return;
    parts_.selfcal->overlay_shown(overlay_id_, overlay_image_);
    overlay_told_ = true;
}

void Kiosk::note_rejections(const std::vector<DecodeWorker::Rejection>& rejections) {
    // Counted from the worker's total: take() keeps only the latest reasons.
    const std::uint64_t total = parts_.inbox.rejected();
    for (; rejections_seen_ < total; ++rejections_seen_) parts_.display.stats().rejected();
    const std::uint64_t on_screen = current_ ? current_->request_id : 0;
    for (const auto& r : rejections) {
        // The first ten, then every hundredth: a farm sending garbage must not flood the journal.
        if (r.number <= 10 || r.number % 100 == 0) {
            spdlog::warn("frame dropped ({} so far): {}; keeping request {} on screen", r.number, r.why, on_screen);
        }
        note_error(fmt::format("frame dropped ({} so far): {}", r.number, r.why));
    }
}

void Kiosk::check_frames_shown() {
    const std::uint64_t shown = parts_.display.frames_on_screen();
    if (shown == frames_seen_) return;
    frames_seen_ = shown;
    if (options_.frames > 0 && shown >= options_.frames) {
        spdlog::info("stopping: {} frames shown (--frames)", shown);
        loop_.stop();
    }
}

void Kiosk::on_tick() {
    auto expirations = tick_.drain();
    if (!expirations) return fail("display tick", expirations.error().message);
    if (*expirations == 0) return;
    const auto now = std::chrono::steady_clock::now();
    if (options_.duration_s > 0 && std::chrono::duration<double>(now - start_).count() >= options_.duration_s) {
        spdlog::info("stopping: {} s elapsed (--duration-s)", options_.duration_s);
        loop_.stop();
        return;
    }
    submit_next_view();
    const LinkClientStats link = parts_.link.stats();
    note_link_state(link);
    // A pattern pair holds the frame, its shift included: the pair's two camera frames must differ
    // by the pattern alone (and a repaint would keep a KMS output's flip pending at every tick).
    const bool holding = pattern_base_.has_value();
    if (!holding) (void)update_late_warp();
    // Nothing new since the previous tick: show the current frame again if the wall would change
    // (the late warp's new shift; an unchanged wall is not drawn again: on a software rasteriser a
    // round of three outputs is tens of ms of CPU taken from the farm). A frame shown since then
    // already carried the shift of its own round, and a frame already decoded and waiting is shown
    // next, with this tick's shift: a repaint first would only delay it by a whole round. A turn
    // after that round reaches the wall with the next frame or at the next tick, whichever comes
    // first.
    // On a slow rasteriser the repaints also leave it rest between rounds ([display].late_warp_duty).
    if (!holding && !shown_since_tick_ && !frame_waiting() && repaint_pacer_.may_repaint(now)) {
        const std::uint64_t rounds = parts_.display.stats().rounds();
        parts_.display.repaint();
        if (parts_.display.stats().rounds() != rounds) repaint_pacer_.drew(now, std::chrono::steady_clock::now());
        check_frames_shown();
    }
    shown_since_tick_ = false;
    update_wall(now);
    update_pattern_overlay();
    // A copy at the monitor's rate (2 Hz), not the display's: the worker converts it on its thread.
    if (parts_.selfcal != nullptr && current_ && parts_.selfcal->wants_content())
        parts_.selfcal->offer(current_->image);
    if (const auto stuck = flip_overdue(now)) {
        return fail("output", fmt::format("{}: its page flip has not completed for over {:.1f} s; stopping so that "
                                          "the service manager restarts the kiosk",
                                          parts_.display.output_name(*stuck),
                                          std::chrono::duration<double>(options_.flip_timeout).count()));
    }
    if (std::chrono::duration<double>(now - last_status_).count() >= config_.stats.status_period_s) {
        write_status(running_state());
    }
    if (std::chrono::duration<double>(now - last_log_).count() >= config_.stats.log_period_s) {
        spdlog::info("stats: {} link_sessions={} link_connected={} memory_release_max_ms={:.1f}",
                     parts_.display.stats().log_line(), link.sessions_opened, link.connected, memory_release_.max_ms());
        last_log_ = now;
    }
    memory_release_.tick(now);  // months on the wall: freed memory goes back (common/memory_release.h)
    parts_.notifier.watchdog();
}

bool Kiosk::frame_waiting() const {
    pollfd inbox{parts_.inbox.fd(), POLLIN, 0};
    return ::poll(&inbox, 1, 0) == 1 && (inbox.revents & POLLIN) != 0;
}

bool Kiosk::update_late_warp() {
    ContentTransform t;  // identity: no band
    // Every request carries the band, so every farm frame spans its arc (whatever pixel size the
    // farm rendered it at: the transform is in normalised content coordinates).
    if (guard_ && current_) {
        const ContentShift shift =
            late_rotational_shift(config_.screen.arc_deg, guard_->guard_deg, latest_yaw_deg_ - current_->pose.yaw_deg);
        t.scale_u = static_cast<float>(shift.scale);
        t.offset_u = static_cast<float>(shift.offset);
        if (shift.clamped) ++late_warp_clamped_;
    }
    const ContentTransform before = parts_.display.content_transform();
    parts_.display.set_content_transform(t);
    return t != before;
}

void Kiosk::submit_next_view() {
    KioskNavigation::Step step = parts_.navigation.next();
    latest_yaw_deg_ = step.request.pose.yaw_deg;
    if (guard_ && std::holds_alternative<CylinderScreen>(step.request.camera)) {
        // The farm renders the band too: the same degrees per column, wider (late_warp.h).
        std::get<CylinderScreen>(step.request.camera).arc_deg = guard_->camera.arc_deg;
        step.request.size.width = guard_->size.width;
    }
    std::string why;
    step.entry.request_id = parts_.link.submit(step.request, &why);
    if (step.entry.request_id == 0) {
        spdlog::error("view request refused: {}", why);
        note_error("view request refused: " + why);
    }
    step.entry.tick = ++ticks_;
    step.entry.pose = step.request.pose;
    write_pose(step.entry);
    if (step.replay_ended) {
        spdlog::info("stopping: the tracking replay ended (replay_end = \"stop\")");
        loop_.stop();
    }
}

void Kiosk::write_pose(const PoseLogEntry& entry) {
    if (!options_.pose_log) return;
    try {
        options_.pose_log->write(entry);
    } catch (const std::exception& e) {
        spdlog::error("--pose-log: {}; no more poses are logged", e.what());
        note_error(std::string("pose log: ") + e.what());
        options_.pose_log.reset();
    }
}

void Kiosk::note_link_state(const LinkClientStats& link) {
    if (link.connected == connected_) return;
    connected_ = link.connected;
    const char* state = connected_ ? "connected" : "disconnected";
    spdlog::info("farm {} {}; showing {}", config_.farm.endpoint, state, showing(current()));
    parts_.display.stats().event(realtime_ns(), state, current_ ? current_->request_id : 0);
}

std::optional<std::size_t> Kiosk::flip_overdue(std::chrono::steady_clock::time_point now) {
    if (options_.flip_timeout <= std::chrono::steady_clock::duration::zero()) return std::nullopt;  // off
    if (!parts_.display.overdue_output(now, options_.flip_timeout)) return std::nullopt;
    // A flip event may be waiting behind this tick in the same poll round: take it first, but only
    // if one is there (dispatching reads the DRM fd, which would block otherwise).
    pollfd events{parts_.display.event_fd(), POLLIN, 0};
    if (::poll(&events, 1, 0) == 1 && (events.revents & POLLIN) != 0) on_flip();
    return parts_.display.overdue_output(now, options_.flip_timeout);
}

void Kiosk::on_flip() {
    if (Status s = parts_.display.on_flip(); !s) return fail("output events", s.error().message);
    check_frames_shown();
    tell_overlay_shown();
}

void Kiosk::on_calibration() {
    std::optional<CalibrationUpdate> update = parts_.calibration->take();
    if (!update) return;
    for (const auto& n : update->notes) spdlog::info("calibration: {}", n);
    std::string why = update->error;
    if (update->screen) {
        if (Status s = parts_.display.swap_calibration(std::move(*update->screen)); s) {
            calibration_.source = update->source;
            calibration_.loaded_ns =
                std::chrono::duration_cast<std::chrono::nanoseconds>(update->loaded_at.time_since_epoch()).count();
            calibration_.last_error.clear();
            ++calibration_.swaps;
            if (update->source == "selfcal") ++selfcal_swaps_;
            spdlog::info("calibration: now showing {} (swap {})", update->source, calibration_.swaps);
            check_frames_shown();
            write_status(running_state());
            return;
        } else {
            why = fmt::format("{}: cannot be put on the outputs: {}", update->source, s.error().message);
        }
    }
    calibration_.last_error = why;
    calibration_.last_error_ns = realtime_ns();
    ++calibration_.refused;
    spdlog::error("calibration: {}; keeping {} on the outputs", why, calibration_.source);
    write_status(running_state());
}

bool Kiosk::status_panel_wanted() const {
    switch (config_.status.on_wall) {
        case OnWall::off:
            return false;
        case OnWall::always:
            return true;
        case OnWall::on_demand:
            return panel_toggled_ || file_exists(config_.status.trigger_file);
    }
    return false;
}

std::vector<std::string> Kiosk::wall_lines(std::chrono::steady_clock::time_point now) const {
    std::vector<std::string> lines;
    if (status_panel_wanted()) lines = status_panel_lines(status(running_state()));
    const double silent_s = std::chrono::duration<double>(now - last_frame_at_).count();
    const double lost_after = config_.status.farm_lost_after_s;
    if (current_ && lost_after > 0 && silent_s >= lost_after) lines.push_back(farm_lost_line(silent_s));
    if (config_.status.on_wall != OnWall::off) {
        for (const StartFallback& f : options_.fallbacks) lines.push_back(f.wall);
    }
    return lines;
}

Rgb8Image Kiosk::with_wall_lines(const Rgb8Image& content) const {
    Rgb8Image out = content;
    draw_on_wall(out, parts_.display.calibration(), wall_lines_);
    return out;
}

void Kiosk::update_wall(std::chrono::steady_clock::time_point now) {
    if (!current_) return;  // the connecting card says enough
    std::vector<std::string> lines = wall_lines(now);
    if (lines == wall_lines_) return;
    if (lines.empty() != wall_lines_.empty()) {
        spdlog::info("on-wall status: {}",
                     lines.empty() ? std::string("off") : fmt::format("{}", fmt::join(lines, " | ")));
    }
    wall_lines_ = std::move(lines);
    if (pattern_base_) return;  // a pattern pair is on the wall: its end redraws with these lines
    parts_.display.refresh_content(with_wall_lines(current_->image));
}

const char* Kiosk::running_state() const {
    if (!current_) return "connecting";
    return connected_ ? "showing" : "disconnected";
}

KioskStatus Kiosk::status(const char* state) const {
    KioskStatus s;
    s.written_ns = realtime_ns();
    s.uptime_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    s.state = state;
    s.endpoint = config_.farm.endpoint;
    s.connected = connected_;
    s.frames_shown = parts_.display.frames_on_screen();
    s.showing_request = current_ ? current_->request_id : 0;
    s.calibration = calibration_;
    if (parts_.selfcal != nullptr) s.selfcal = parts_.selfcal->status();
    s.on_wall = wall_lines_;
    for (const StartFallback& f : options_.fallbacks) s.fallbacks.push_back(f.message);
    if (current_)
        s.farm_silent_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - last_frame_at_).count();
    const StatsSummary window = parts_.display.stats().window_summary();
    s.fps = window.fps;
    s.latency_mean_ms = window.latency_mean_ms;
    s.latency_p95_ms = window.latency_p95_ms;
    s.last_error = last_error_;
    s.last_error_ns = last_error_ns_;
    if (parts_.link.stats) s.certificates = parts_.link.stats().certificates;
    s.certificate_warning_days = config_.status.certificate_warning_days;
    return s;
}

void Kiosk::write_status(const char* state) {
    if (config_.stats.status_file.empty() && config_.stats.metrics_file.empty()) return;
    last_status_ = std::chrono::steady_clock::now();
    const KioskStatus now = status(state);
    if (!config_.stats.status_file.empty()) {
        try {
            write_kiosk_status(config_.stats.status_file, now);
            if (status_failing_) spdlog::info("status file: {} written again", config_.stats.status_file.string());
            status_failing_ = false;
        } catch (const std::exception& e) {
            // Once, not every period: the display goes on either way.
            if (!status_failing_) spdlog::warn("status file: {}; trying again every period", e.what());
            note_error(std::string("status file: ") + e.what());
            status_failing_ = true;
        }
    }
    write_metrics(now);
}

void Kiosk::write_metrics(const KioskStatus& now) {
    if (config_.stats.metrics_file.empty()) return;
    KioskCounters counters;
    counters.motion_to_photon = &parts_.display.stats().motion_to_photon();
    if (parts_.link.stats) counters.link = parts_.link.stats();
    counters.frames_dropped = parts_.inbox.rejected();
    if (parts_.selfcal != nullptr) counters.selfcal_corrections = parts_.selfcal->corrections();
    counters.selfcal_swaps = selfcal_swaps_;
    counters.version = cli::version();
    try {
        write_kiosk_metrics(config_.stats.metrics_file, now, counters);
        if (metrics_failing_) spdlog::info("metrics file: {} written again", config_.stats.metrics_file.string());
        metrics_failing_ = false;
    } catch (const std::exception& e) {
        if (!metrics_failing_) spdlog::warn("metrics file: {}; trying again every period", e.what());
        note_error(std::string("metrics file: ") + e.what());
        metrics_failing_ = true;
    }
}

int Kiosk::finish() {
    parts_.notifier.stopping();
    parts_.navigation.stop();
    parts_.link.stop();
    if (options_.pose_log) {
        try {
            options_.pose_log->close();
        } catch (const std::exception& e) {
            spdlog::error("--pose-log: {}", e.what());
            if (exit_code_ == 0) exit_code_ = 1;
        }
    }
    const nlohmann::json navigation = parts_.navigation.report(ticks_);
    const LinkClientStats link = parts_.link.stats();
    spdlog::info("stats: {} link_sessions={}", parts_.display.stats().log_line(), link.sessions_opened);
    if (config_.outputs.composite) parts_.display.write_composite();
    write_statistics(navigation, link);
    write_status("stopped");
    return exit_code_;
}

void Kiosk::write_statistics(const nlohmann::json& navigation, const LinkClientStats& link) {
    if (config_.stats.file.empty()) return;
    const RunRecord run{config_.farm.endpoint,        config_.quality.content,
                        config_.quality.jpeg_quality, navigation,
                        link_stats_json(link),        exit_code_};
    try {
        parts_.display.stats().write_json(config_.stats.file, run_stats_json(run));
        spdlog::info("statistics: {}", config_.stats.file.string());
    } catch (const std::exception& e) {
        spdlog::error("statistics: {}", e.what());
        if (exit_code_ == 0) exit_code_ = 1;
    }
}

}  // namespace mogao
