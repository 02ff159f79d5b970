// SPDX-License-Identifier: Apache-2.0
#include "kiosk/selfcal_worker.h"

#include <array>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>

#include "common/srgb.h"

namespace mogao {

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

selfcal::SelfcalStatus SelfcalWorker::status() const {
    const std::lock_guard lock(mutex_);
    return status_;
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
        monitor(content, std::chrono::duration<double>(now - start_).count());
        next = std::max(next + period_, now);  // at most rate_hz; a slow step is not caught up
    }
}

void SelfcalWorker::monitor(const Rgb8Image& content, double t_s) {
    selfcal::StepResult r;
    try {
        const cv::Mat1f grey = linear_grey(content, kMonitorWidth);
        const std::uint64_t frame = steps();
        const cv::Mat1f camera = camera_(grey, calibrator_.calibration(), frame);
        r = calibrator_.step(grey, camera, t_s);
    } catch (const std::exception& e) {
        spdlog::error("selfcal: t={:.1f}s: {}; frame skipped", t_s, e.what());
        return;
    }
    for (const std::string& line : r.journal) spdlog::info("selfcal: {}", line);
    selfcal::SelfcalState before;
    {
        const std::lock_guard lock(mutex_);
        before = status_.state;
        status_ = r.status;
        ++steps_;
    }
    if (r.status.state != before || steps() == 1) spdlog::info("{}", r.status.text());
    if (r.calibration) {
        CalibrationUpdate update;
        update.source = "selfcal";
        update.screen = std::move(r.calibration);
        inbox_.put(std::move(update));
    }
}

}  // namespace mogao
