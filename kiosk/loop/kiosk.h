// SPDX-License-Identifier: Apache-2.0
// Kiosk: the appliance's display loop (docs/kiosk.md, "The event loop"). One poll(2) loop on the main
// thread over four fds, one handler each:
//   on_signal  signalfd: SIGINT/SIGTERM -> clean stop; SIGUSR2 -> the status panel on/off on the wall
//   on_frame   the FrameInbox's eventfd: take the newest farm frame its worker thread decoded (a
//              frame that failed was dropped there; the last good one stays) and show it on every
//              output
//   on_tick    timerfd ([display].rate_hz): --duration-s; next pose from the navigation; submit the view
//              request; link state changes; idle repaint (also when the late warp's shift changed:
//              [screen].guard_deg > 0, appliance/warp/late_warp.h); periodic stats line; WATCHDOG=1
//   on_flip    the backend's event fd (KMS page flips): pending content onto outputs ready again
//              and, with self-recalibration, hands the frame on the wall to its worker when it asks
//   on_calibration  the CalibrationInbox's eventfd (when given): a calibration loaded and validated
//              off this thread (a changed MPCDI file, self-recalibration) is swapped onto the outputs;
//              an unusable one is logged (file and field) and the last good one stays on the wall
// The handlers are public so that tests can drive them one at a time (kiosk/loop/kiosk_test.cpp).
// run() loops until a stop (signal, --frames N on screen, --duration-s, end of a tracking replay), then
// makes the clean stop: STOPPING=1, navigation, link, pose log, final stats line, composite, JSON.
//
// The parts are made by kiosk/main.cpp (kiosk/loop/kiosk_setup.h) and outlive the Kiosk. Loop thread only
// (the link's thread only touches the FrameInbox). Errors per docs/architecture.md: a bad frame is
// dropped and logged; a broken fd stops the loop with exit code 1; run() returns the exit code.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "appliance/decode/last_good_frame.h"
#include "appliance/warp/late_warp.h"
#include "common/event_loop.h"
#include "common/memory_release.h"
#include "common/service_notify.h"
#include "common/signal_fd.h"
#include "common/timer_fd.h"
#include "common/view_request.h"
#include "kiosk/config/kiosk_config.h"
#include "kiosk/config/last_loaded.h"
#include "kiosk/display/content_dump.h"
#include "kiosk/display/kiosk_display.h"
#include "kiosk/live_calibration/calibration_inbox.h"
#include "kiosk/live_calibration/selfcal_worker.h"
#include "kiosk/loop/frame_inbox.h"
#include "kiosk/loop/repaint_pacer.h"
#include "kiosk/navigation/kiosk_navigation.h"
#include "kiosk/navigation/pose_log.h"
#include "kiosk/stats/kiosk_status.h"
#include "renderfarm/link/link_client.h"

namespace mogao {

// What the loop needs of the link: mogao-kiosk wires a LinkClient (link_of); tests may record.
struct KioskLink {
    std::function<std::uint64_t(ViewRequest, std::string*)> submit;  // LinkClient::submit
    std::function<LinkClientStats()> stats;
    std::function<void()> stop;  // no frame callback runs afterwards
};
[[nodiscard]] KioskLink link_of(LinkClient& client);

// The parts the loop drives, in pipeline order.
struct KioskParts {
    KioskDisplay& display;
    FrameInbox& inbox;
    KioskLink link;
    KioskNavigation& navigation;
    const SignalFd& signals;
    ServiceNotifier& notifier;
    CalibrationInbox* calibration = nullptr;  // run-time calibration swaps; nullptr: none
    // Self-recalibration ([selfcal] enabled): the tick offers it the frame on the wall when it asks;
    // its status goes into the status file; its corrections arrive through `calibration`. nullptr: off.
    SelfcalWorker* selfcal = nullptr;
};

// What the command line adds: stop conditions and records of the run.
struct KioskRunOptions {
    std::uint64_t frames = 0;         // --frames: stop once this many farm frames are on screen (0: never)
    double duration_s = 0;            // --duration-s (0: never)
    std::optional<ContentDump> dump;  // --dump-content
    std::optional<PoseLog> pose_log;  // --pose-log
    // When positive: an output whose page flip has not completed for this long fails the kiosk
    // (exit 1, the watchdog no longer fed) so that systemd restarts it. Off (zero) by default: in
    // the QEMU boot test (llvmpipe under TCG draws a round of three outputs in seconds and the
    // flip event waits behind it) a 3 s limit restarted a healthy kiosk, and a longer one has not
    // been proven there yet (docs/kiosk.md).
    std::chrono::steady_clock::duration flip_timeout{0};
    // Start-up files that were bad and replaced by their last good copies (kiosk_setup.h): shown on
    // the wall (unless [status].on_wall = "off") and in the status file for the whole run.
    std::vector<StartFallback> fallbacks{};
};

class Kiosk {
public:
    // Creates and arms the display tick and watches the four fds. Throws KioskSetupError (exit 1,
    // "display tick: ...") when the timerfd cannot be made.
    Kiosk(const KioskConfig& config, KioskParts parts, KioskRunOptions options);
    Kiosk(const Kiosk&) = delete;
    Kiosk& operator=(const Kiosk&) = delete;

    // Loops until a stop, then the clean stop. Returns the exit code (0 stopped, 1 failure).
    [[nodiscard]] int run();

    void on_signal();
    void on_frame();
    void on_tick();
    void on_flip();
    void on_calibration();

    [[nodiscard]] bool stopping() const { return loop_.stopping(); }
    [[nodiscard]] int exit_code() const { return exit_code_; }
    [[nodiscard]] std::uint64_t ticks() const { return ticks_; }
    // The frame on screen; nullptr before the first good farm frame.
    [[nodiscard]] const ContentFrame* current() const { return current_ ? &*current_ : nullptr; }
    [[nodiscard]] int tick_fd() const { return tick_.fd(); }
    [[nodiscard]] std::uint64_t late_warp_clamped() const { return late_warp_clamped_; }
    [[nodiscard]] const CalibrationInUse& calibration_in_use() const { return calibration_; }
    [[nodiscard]] const std::vector<std::string>& on_wall() const { return wall_lines_; }

    // The status file now (KioskStatus; the tick rewrites it every [stats].status_period_s).
    [[nodiscard]] KioskStatus status(const char* state) const;

    // The clean stop after the loop (run() calls it); returns the exit code.
    [[nodiscard]] int finish();

private:
    void fail(const char* what, const std::string& message);  // logs, exit code 1, stops the loop
    void note_error(std::string what);                        // the status file's last_error (the caller logs it)
    [[nodiscard]] std::optional<std::size_t> flip_overdue(std::chrono::steady_clock::time_point now);
    // Sets the display's content transform for the yaw turned since the current frame's request
    // (identity without a guard band); true when it changed.
    [[nodiscard]] bool update_late_warp();
    // A decoded frame is waiting in the inbox (its eventfd is readable): on_frame() shows it next.
    [[nodiscard]] bool frame_waiting() const;
    void note_rejections(const std::vector<DecodeWorker::Rejection>& rejections);  // counts and logs
    void check_frames_shown();                                                     // --frames
    void submit_next_view();
    void note_link_state(const LinkClientStats& link);
    void write_pose(const PoseLogEntry& entry);
    void write_statistics(const nlohmann::json& navigation, const LinkClientStats& link);
    void write_status(const char* state);        // [stats].status_file and metrics_file (no-op when both empty)
    void write_metrics(const KioskStatus& now);  // [stats].metrics_file (kiosk_metrics.h; no-op when empty)
    // The on-wall lines wanted now: the status panel when asked for ([status].on_wall, SIGUSR2,
    // trigger file) and the farm-lost indicator; empty: the picture alone.
    [[nodiscard]] std::vector<std::string> wall_lines(std::chrono::steady_clock::time_point now) const;
    [[nodiscard]] bool status_panel_wanted() const;
    // Redraws the current frame when the wanted lines changed (the tick).
    void update_wall(std::chrono::steady_clock::time_point now);
    [[nodiscard]] Rgb8Image with_wall_lines(const Rgb8Image& content) const;
    // The current frame to the outputs (with the on-wall lines), counted as a farm frame.
    void show_current();
    // The self-calibration's pattern pair (SelfcalWorker::overlay, the tick): shows a new overlay on
    // the held frame, tells the worker once every output has completed it, and when the overlay is
    // withdrawn shows the content again (a frame that arrived meanwhile is shown then).
    void update_pattern_overlay();
    void tell_overlay_shown();  // the worker, once every output completed the overlay's present
    [[nodiscard]] const char* running_state() const;

    const KioskConfig& config_;
    KioskParts parts_;
    KioskRunOptions options_;
    EventLoop loop_;
    TimerFd tick_;
    std::optional<ContentFrame> current_;
    std::optional<GuardedScreen> guard_;   // [screen].guard_deg > 0: the band the farm renders
    double latest_yaw_deg_ = 0;            // the navigation's yaw at the latest tick
    std::uint64_t late_warp_clamped_ = 0;  // updates whose turn exceeded the band
    std::uint64_t rejections_seen_ = 0;
    std::uint64_t ticks_ = 0;
    std::uint64_t frames_seen_ = 0;
    bool connected_ = false;
    CalibrationInUse calibration_;
    bool shown_since_tick_ = true;
    std::chrono::steady_clock::time_point start_;
    std::chrono::steady_clock::time_point last_log_;
    MemoryRelease memory_release_;
    RepaintPacer repaint_pacer_;  // [display].late_warp_duty
    std::chrono::steady_clock::time_point last_status_;
    bool status_failing_ = false;      // the status file's last write failed (logged once)
    bool metrics_failing_ = false;     // the metrics file's last write failed (logged once)
    std::uint64_t selfcal_swaps_ = 0;  // of calibration_.swaps, those from self-recalibration
    std::string last_error_;           // KioskStatus::last_error
    std::int64_t last_error_ns_ = 0;
    bool panel_toggled_ = false;           // SIGUSR2 with [status].on_wall = "on_demand"
    std::vector<std::string> wall_lines_;  // drawn on the frame on the wall now
    // While a pattern pair is shown: the frame it is drawn on (with the on-wall lines of its start),
    // held still so that the pair's camera frames differ by the pattern alone.
    std::optional<Rgb8Image> pattern_base_;
    std::uint64_t overlay_id_ = 0;                         // the overlay on the wall (0: none)
    Rgb8Image overlay_image_;                              // pattern_base_ with that overlay, as shown
    bool overlay_told_ = false;                            // the worker was told it is shown
    bool frame_held_back_ = false;                         // a farm frame arrived while the pair was shown
    std::uint64_t held_back_replaced_ = 0;                 // held-back frames replaced before they were shown
    std::chrono::steady_clock::time_point last_frame_at_;  // the latest new farm frame
    int exit_code_ = 0;
};

}  // namespace mogao
