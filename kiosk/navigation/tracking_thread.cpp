// SPDX-License-Identifier: Apache-2.0
#include "kiosk/navigation/tracking_thread.h"

#include <cerrno>
#include <chrono>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "appliance/navigation/tag_sample_of.h"
#include "drivers/camera/camera_source.h"

namespace mogao {
namespace {

TrackerConfig tracker_config(const TrackingConfig& c) {
    TrackerConfig t;
    t.detector = c.detector;
    t.roi = c.roi;
    t.camera = c.intrinsics;
    t.tag_size_m = c.tag_size_m;
    t.tag_id = c.tag_id;
    return t;
}

// The first five, then every hundredth: a broken camera must not flood the journal.
bool worth_logging(std::uint64_t n) { return n <= 5 || n % 100 == 0; }

}  // namespace

std::int64_t monotonic_ns() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

TrackingThread::TrackingThread(const TrackingConfig& config, TagSampleQueue& queue)
    : spec_(config.source), tracker_(tracker_config(config)), queue_(queue) {
    spec_.timeout_ms = 1000;  // bounds how long stop() waits for a stalled camera
    auto opened = open_camera_source(spec_);
    if (!opened) throw std::runtime_error("[navigation].camera = '" + config.camera + "': " + opened.error().message);
    source_ = std::move(opened).value();
    description_ = source_->description();
    thread_ = std::thread([this] { run(); });
}

TrackingThread::~TrackingThread() { stop(); }

void TrackingThread::stop() {
    {
        const std::lock_guard lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
}

TrackingCounters TrackingThread::counters() const {
    const std::lock_guard lock(mutex_);
    return counters_;
}

void TrackingThread::count(std::uint64_t TrackingCounters::*field) {
    const std::lock_guard lock(mutex_);
    ++(counters_.*field);
}

bool TrackingThread::wait_until(std::int64_t deadline_ns) {
    std::unique_lock lock(mutex_);
    const auto deadline = std::chrono::steady_clock::time_point(std::chrono::nanoseconds(deadline_ns));
    wake_.wait_until(lock, deadline, [this] { return stop_; });
    return !stop_;
}

bool TrackingThread::reopen_source() {
    // Once a second, until it opens or the thread is stopped.
    if (!wait_until(monotonic_ns() + 1'000'000'000)) return false;
    auto opened = open_camera_source(spec_);
    if (!opened) {
        spdlog::warn("tracking: camera {} still unavailable: {}", description_, opened.error().message);
        return true;
    }
    source_ = std::move(opened).value();
    count(&TrackingCounters::reopens);
    spdlog::info("tracking: camera re-opened: {}", source_->description());
    return true;
}

bool TrackingThread::on_frame_error(int code, const std::string& message) {
    if (code == ENODATA) {
        spdlog::info("tracking: the replay ended ({} frames)", counters().frames);
        {
            const std::lock_guard lock(mutex_);
            counters_.ended = true;
        }
        queue_.close();
        return false;
    }
    if (code == ETIMEDOUT) {
        count(&TrackingCounters::timeouts);
        if (worth_logging(counters().timeouts)) spdlog::warn("tracking: {}", message);
        return true;
    }
    if (code == EBADMSG) {
        count(&TrackingCounters::frame_errors);
        if (worth_logging(counters().frame_errors)) spdlog::warn("tracking: frame skipped: {}", message);
        return true;
    }
    spdlog::error("tracking: camera failed, re-opening it every second: {}", message);
    source_.reset();
    return true;
}

void TrackingThread::run() {
    bool rebased = false;
    std::int64_t offset_ns = 0;  // replay timestamp -> CLOCK_MONOTONIC
    for (;;) {
        {
            const std::lock_guard lock(mutex_);
            if (stop_) return;
        }
        if (!source_) {
            if (!reopen_source()) return;
            continue;
        }
        if (rebased) {
            // A replay behind its clock: drop what is already stale before decoding it (a PNG
            // decode costs several times the tracking); the check below catches the rest.
            if (const std::uint64_t dropped = source_->skip_frames_due_by(monotonic_ns() - offset_ns); dropped > 0) {
                const std::lock_guard lock(mutex_);
                counters_.skipped += dropped;
            }
        }
        auto frame = source_->next_frame();
        if (!frame) {
            if (!on_frame_error(frame.code(), frame.error().message)) return;
            continue;
        }
        std::int64_t time_ns = frame->timestamp_ns;
        if (frame->clock == TimestampSource::replay) {
            if (!rebased) {
                offset_ns = monotonic_ns() - frame->timestamp_ns;
                rebased = true;
            }
            time_ns = frame->timestamp_ns + offset_ns;
            // A live camera hands out its newest frame (V4L2 capture keeps only the newest), so a
            // tracker slower than the camera skips frames instead of falling further and further
            // behind. A replay does the same: a frame whose successor is already due is dropped;
            // otherwise the Navigator would get samples older than its hold_s and stop tracking.
            if (const auto next = source_->next_capture_time_ns(); next && *next + offset_ns <= monotonic_ns()) {
                count(&TrackingCounters::skipped);
                continue;
            }
            if (!wait_until(time_ns)) return;  // released at its capture time
        }
        TrackedTag tag;
        try {
            tag = tracker_.track(*frame);
        } catch (const std::exception& e) {
            count(&TrackingCounters::frame_errors);
            if (worth_logging(counters().frame_errors))
                spdlog::warn("tracking: frame {} skipped: {}", frame->sequence, e.what());
            continue;
        }
        {
            const std::lock_guard lock(mutex_);
            ++counters_.frames;
            if (tag.visible) ++counters_.visible;
            if (tag.ambiguous) ++counters_.ambiguous;
        }
        queue_.push(tag_sample_of(tag, time_ns));
    }
}

}  // namespace mogao
