// SPDX-License-Identifier: Apache-2.0
// SelfcalWorker: continuous self-recalibration beside the tour (docs/kiosk.md,
// "Self-recalibration"; the maths in appliance/selfcal/self_calibrator.h). Its own thread, never
// the display thread, at most `rate_hz` (2 Hz) monitored frames a second:
//   1. asks the loop for the content frame on the wall (wants_content(); the loop's tick offer()s a
//      copy of the frame it shows, so the loop copies at the monitor's rate, not the display's);
//   2. turns it into linear grey (IEC 61966-2-1 decoding, Rec. 709 luma weights), downscaled to at
//      most kMonitorWidth columns (the monitor's features do not need more);
//   3. takes a camera frame of the screen (the Camera callback: a live camera, or in tests and
//      demos the virtual rig's simulated view of what the projectors show);
//   4. calls SelfCalibrator::step, logs its journal lines (and the status line when the state
//      changes), publishes the status (status(), read by the status file) and puts every new
//      ScreenCalibration it returns into the CalibrationInbox as source "selfcal" -- the run-time
//      swap puts it on the wall; the correction's interpolation over transition_s is
//      SelfCalibrator's (selfcal::interpolate_calibration).
// The content-independent fallback ([selfcal] pattern = true; selfcal::PatternOptions): while the
// calibrator wants a pattern pair (the content gave too little evidence), a monitored frame is a
// pair instead: the worker publishes overlay() +a P, waits until the loop has shown it on every
// output (overlay_shown(), with the frame as shown), takes a camera frame, does the same with -a P,
// withdraws the overlay and calls SelfCalibrator::step_pattern. The loop holds the content frame
// still for the pair (new farm frames wait; a few display ticks), so that the two camera frames
// differ only by the pattern. The camera must expose after the flip: the rig camera renders what
// it is given; a V4L2 camera's next frame is assumed to be (not checked on hardware).
// Off by default ([selfcal] enabled = false). Errors: a step or camera that throws is logged (with
// the frame's time) and that frame is skipped; a pattern the loop does not show within
// kOverlayTimeout is withdrawn and the pair skipped; the worker goes on.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

#include <opencv2/core.hpp>

#include "appliance/selfcal/self_calibrator.h"
#include "common/image.h"
#include "kiosk/live_calibration/calibration_inbox.h"

namespace mogao {

class SelfcalWorker {
public:
    static constexpr int kMonitorWidth = 960;
    static constexpr std::chrono::seconds kOverlayTimeout{5};

    // A camera frame of the screen while `content` (linear grey, what the wall shows) is on the wall
    // through `wall`; CV_32FC1 in [0, 1], the camera's resolution. `frame` counts monitored frames.
    using Camera =
        std::function<cv::Mat1f(const cv::Mat1f& content, const ScreenCalibration& wall, std::uint64_t frame)>;

    // Starts the thread. `inbox` must outlive the worker. rate_hz in (0, 30].
    SelfcalWorker(selfcal::SelfCalibrator calibrator, Camera camera, CalibrationInbox& inbox, double rate_hz);
    ~SelfcalWorker();  // stops and joins
    SelfcalWorker(const SelfcalWorker&) = delete;
    SelfcalWorker& operator=(const SelfcalWorker&) = delete;

    // Loop thread: true when the worker waits for the frame on the wall; then offer() it.
    [[nodiscard]] bool wants_content() const { return wants_.load(std::memory_order_acquire); }
    void offer(const Rgb8Image& content);

    // The fallback's pattern on the wall (see header): `signed_pattern` (CV_32FC1, the size of the
    // content frame it was made for) is added to the content's linear light (IEC 61966-2-1) before
    // it is warped; `id` numbers the overlays from 1.
    struct Overlay {
        std::uint64_t id = 0;
        cv::Mat1f signed_pattern;
    };
    // Loop thread: the overlay to show now; nullopt: the content alone.
    [[nodiscard]] std::optional<Overlay> overlay() const;
    // Loop thread: overlay `id` has reached every output; `shown` is the content frame as shown.
    void overlay_shown(std::uint64_t id, const Rgb8Image& shown);

    // Any thread: the latest step's status (calibrated before the first).
    [[nodiscard]] selfcal::SelfcalStatus status() const;
    [[nodiscard]] std::uint64_t steps() const;
    [[nodiscard]] std::uint64_t pattern_pairs() const;  // steps that were pattern pairs
    [[nodiscard]] std::uint64_t corrections() const;    // times the state became correcting

private:
    void run();
    void monitor(const Rgb8Image& content, double t_s);
    void monitor_pattern_pair(const Rgb8Image& content, double t_s);
    // Publishes `pattern` and waits for the loop to show it; the frame as shown, or nullopt when
    // stopping or after kOverlayTimeout.
    std::optional<Rgb8Image> show_overlay(cv::Mat1f pattern);
    void withdraw_overlay();
    [[nodiscard]] bool stopping() const;
    cv::Mat1f capture(const cv::Mat1f& content);
    void publish(selfcal::StepResult r, bool pattern_pair);

    selfcal::SelfCalibrator calibrator_;  // the worker's thread only
    Camera camera_;
    CalibrationInbox& inbox_;
    std::chrono::steady_clock::duration period_;
    std::chrono::steady_clock::time_point start_;
    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::optional<Rgb8Image> offered_;
    bool stop_ = false;
    std::atomic<bool> wants_{false};
    std::optional<Overlay> overlay_;
    std::uint64_t overlay_ids_ = 0;
    std::optional<std::pair<std::uint64_t, Rgb8Image>> overlay_shown_;  // the loop's answer
    std::uint64_t captures_ = 0;  // camera frames taken (the worker's thread only)
    selfcal::SelfcalStatus status_;
    std::uint64_t steps_ = 0;
    std::uint64_t pattern_pairs_ = 0;
    std::uint64_t corrections_ = 0;
    std::thread thread_;  // last
};

// `content` (sRGB RGB8) with `signed_pattern` added to each channel's linear light, clamped to
// [0, 1] and encoded again (IEC 61966-2-1); a pattern of another size is resized to the content's
// (bilinear). Pure.
[[nodiscard]] Rgb8Image with_pattern(const Rgb8Image& content, const cv::Mat1f& signed_pattern);

// sRGB RGB8 -> linear grey (IEC 61966-2-1, Rec. 709 luma), area-downscaled to at most `max_width`
// columns (aspect kept). Pure.
[[nodiscard]] cv::Mat1f linear_grey(const Rgb8Image& srgb, int max_width);

}  // namespace mogao
