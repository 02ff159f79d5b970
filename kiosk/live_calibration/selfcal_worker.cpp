// SPDX-License-Identifier: Apache-2.0
#include "kiosk/live_calibration/selfcal_worker.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>

#include "common/srgb.h"

namespace mogao {

Rgb8Image with_pattern(const Rgb8Image& content, const cv::Mat1f& signed_pattern) {
    cv::Mat1f pattern = signed_pattern;
    if (pattern.cols != content.size.width || pattern.rows != content.size.height) {
        cv::resize(signed_pattern, pattern, cv::Size(content.size.width, content.size.height), 0, 0, cv::INTER_LINEAR);
    }
    const std::array<float, 256>& decode = srgb8_decode_table();
    Rgb8Image out = content;
    for (int y = 0; y < content.size.height; ++y) {
        for (int x = 0; x < content.size.width; ++x) {
            const float add = pattern(y, x);
            if (add == 0.0f) continue;
            std::uint8_t* p = out.at(x, y);
            for (int c = 0; c < 3; ++c) p[c] = srgb8_encode(static_cast<double>(decode[p[c]] + add));
        }
    }
    return out;
}

cv::Mat1f linear_grey(const Rgb8Image& srgb, int max_width) {
    const std::array<float, 256>& decode = srgb8_decode_table();
    cv::Mat1f grey(srgb.size.height, srgb.size.width);
    for (int y = 0; y < srgb.size.height; ++y) {
        for (int x = 0; x < srgb.size.width; ++x) {
            const std::uint8_t* p = srgb.at(x, y);
            grey(y, x) = 0.2126f * decode[p[0]] + 0.7152f * decode[p[1]] + 0.0722f * decode[p[2]];
        }
    }
    if (max_width <= 0 || grey.cols <= max_width) return grey;
    const int height =
        std::max(1, static_cast<int>(std::lround(grey.rows * static_cast<double>(max_width) / grey.cols)));
    cv::Mat1f small;
    cv::resize(grey, small, cv::Size(max_width, height), 0, 0, cv::INTER_AREA);
    return small;
}

SelfcalWorker::SelfcalWorker(selfcal::SelfCalibrator calibrator, Camera camera, CalibrationInbox& inbox, double rate_hz)
    : calibrator_(std::move(calibrator)), camera_(std::move(camera)), inbox_(inbox) {
    if (!(rate_hz > 0.0 && rate_hz <= 30.0)) throw std::invalid_argument("[selfcal].rate_hz must be in (0, 30]");
    period_ =
        std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(1.0 / rate_hz));
    start_ = std::chrono::steady_clock::now();
    thread_ = std::thread([this] { run(); });
}

SelfcalWorker::~SelfcalWorker() {
    {
        const std::lock_guard lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
}

void SelfcalWorker::offer(const Rgb8Image& content) {
    {
        const std::lock_guard lock(mutex_);
        offered_ = content;
        wants_.store(false, std::memory_order_release);
    }
    wake_.notify_all();
}

std::optional<SelfcalWorker::Overlay> SelfcalWorker::overlay() const {
    const std::lock_guard lock(mutex_);
    return overlay_;
}

void SelfcalWorker::overlay_shown(std::uint64_t id, const Rgb8Image& shown) {
    {
        const std::lock_guard lock(mutex_);
        if (!overlay_ || overlay_->id != id) return;  // withdrawn meanwhile
        overlay_shown_.emplace(id, shown);
    }
    wake_.notify_all();
}

std::uint64_t SelfcalWorker::pattern_pairs() const {
    const std::lock_guard lock(mutex_);
    return pattern_pairs_;
}

selfcal::SelfcalStatus SelfcalWorker::status() const {
    const std::lock_guard lock(mutex_);
    return status_;
}

std::uint64_t SelfcalWorker::corrections() const {
    const std::lock_guard lock(mutex_);
    return corrections_;
}

std::uint64_t SelfcalWorker::steps() const {
    const std::lock_guard lock(mutex_);
    return steps_;
}

void SelfcalWorker::run() {
    auto next = std::chrono::steady_clock::now();
    for (;;) {
        std::unique_lock lock(mutex_);
        if (wake_.wait_until(lock, next, [this] { return stop_; })) return;
        wants_.store(true, std::memory_order_release);
        wake_.wait(lock, [this] { return stop_ || offered_.has_value(); });
        if (stop_) return;
        const Rgb8Image content = std::move(*offered_);
        offered_.reset();
        lock.unlock();
        const auto now = std::chrono::steady_clock::now();
        const double t_s = std::chrono::duration<double>(now - start_).count();
        if (calibrator_.pattern_for_refresh(0, cv::Size(content.size.width, content.size.height))) {
            monitor_pattern_pair(content, t_s);
        } else {
            monitor(content, t_s);
        }
        next = std::max(next + period_, now);  // at most rate_hz; a slow step is not caught up
    }
}

cv::Mat1f SelfcalWorker::capture(const cv::Mat1f& content) {
    // Each capture its own frame number: a simulated camera draws new noise for each.
    return camera_(content, calibrator_.calibration(), captures_++);
}

void SelfcalWorker::monitor(const Rgb8Image& content, double t_s) {
    selfcal::StepResult r;
    try {
        const cv::Mat1f grey = linear_grey(content, kMonitorWidth);
        r = calibrator_.step(grey, capture(grey), t_s);
    } catch (const std::exception& e) {
        spdlog::error("selfcal: t={:.1f}s: {}; frame skipped", t_s, e.what());
        return;
    }
    publish(std::move(r), false);
}

std::optional<Rgb8Image> SelfcalWorker::show_overlay(cv::Mat1f pattern) {
    std::unique_lock lock(mutex_);
    const std::uint64_t id = ++overlay_ids_;
    overlay_ = Overlay{id, std::move(pattern)};
    overlay_shown_.reset();
    const bool shown = wake_.wait_for(lock, kOverlayTimeout, [&] { return stop_ || overlay_shown_.has_value(); });
    if (!shown || stop_) return std::nullopt;
    Rgb8Image frame = std::move(overlay_shown_->second);
    overlay_shown_.reset();
    return frame;
}

void SelfcalWorker::withdraw_overlay() {
    const std::lock_guard lock(mutex_);
    overlay_.reset();
    overlay_shown_.reset();
}

void SelfcalWorker::monitor_pattern_pair(const Rgb8Image& content, double t_s) {
    const cv::Size size(content.size.width, content.size.height);
    std::array<cv::Mat1f, 2> camera;
    selfcal::StepResult r;
    try {
        for (int k = 0; k < 2; ++k) {
            std::optional<cv::Mat1f> pattern = calibrator_.pattern_for_refresh(k, size);
            if (!pattern) throw std::logic_error("the pattern is no longer wanted");
            const std::optional<Rgb8Image> shown = show_overlay(std::move(*pattern));
            if (!shown) {
                withdraw_overlay();
                if (!stopping()) {
                    spdlog::error("selfcal: t={:.1f}s: the display did not show the pattern within {} s; pair skipped",
                                  t_s, kOverlayTimeout.count());
                }
                return;
            }
            camera[static_cast<std::size_t>(k)] = capture(linear_grey(*shown, kMonitorWidth));
        }
        withdraw_overlay();
        r = calibrator_.step_pattern(linear_grey(content, kMonitorWidth), camera[0], camera[1], t_s);
    } catch (const std::exception& e) {
        withdraw_overlay();
        spdlog::error("selfcal: t={:.1f}s: pattern pair: {}; frame skipped", t_s, e.what());
        return;
    }
    publish(std::move(r), true);
}

bool SelfcalWorker::stopping() const {
    const std::lock_guard lock(mutex_);
    return stop_;
}

void SelfcalWorker::publish(selfcal::StepResult r, bool pattern_pair) {
    for (const std::string& line : r.journal) spdlog::info("selfcal: {}", line);
    selfcal::SelfcalState before;
    std::uint64_t steps = 0;
    {
        const std::lock_guard lock(mutex_);
        before = status_.state;
        status_ = r.status;
        steps = ++steps_;
        if (pattern_pair) ++pattern_pairs_;
        if (r.status.state == selfcal::SelfcalState::correcting && before != r.status.state) ++corrections_;
    }
    if (r.status.state != before || steps == 1) spdlog::info("{}", r.status.text());
    if (r.calibration) {
        CalibrationUpdate update;
        update.source = "selfcal";
        update.screen = std::move(r.calibration);
        inbox_.put(std::move(update));
    }
}

}  // namespace mogao
