// SPDX-License-Identifier: Apache-2.0
// SelfcalWorker: continuous self-recalibration beside the tour (issue 14; docs/kiosk.md,
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
// Off by default ([selfcal] enabled = false). Errors: a step or camera that throws is logged (with
// the frame's time) and that frame is skipped; the worker goes on.
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

#include <opencv2/core.hpp>

#include "appliance/selfcal/self_calibrator.h"
#include "common/image.h"
#include "kiosk/calibration_inbox.h"

namespace mogao {

class SelfcalWorker {
public:
    static constexpr int kMonitorWidth = 960;

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

    // Any thread: the latest step's status (calibrated before the first).
    [[nodiscard]] selfcal::SelfcalStatus status() const;
    [[nodiscard]] std::uint64_t steps() const;

private:
    void run();
    void monitor(const Rgb8Image& content, double t_s);

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
    selfcal::SelfcalStatus status_;
    std::uint64_t steps_ = 0;
    std::thread thread_;  // last
};

// sRGB RGB8 -> linear grey (IEC 61966-2-1, Rec. 709 luma), area-downscaled to at most `max_width`
// columns (aspect kept). Pure.
[[nodiscard]] cv::Mat1f linear_grey(const Rgb8Image& srgb, int max_width);

}  // namespace mogao
