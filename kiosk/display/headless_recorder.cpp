// SPDX-License-Identifier: Apache-2.0
#include "kiosk/display/headless_recorder.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "appliance/warp/composite.h"
#include "common/png_io.h"
#include "common/srgb.h"

namespace mogao {

HeadlessRecorder::Writer::Writer() : thread_([this] { run(); }) {}

HeadlessRecorder::Writer::~Writer() {
    {
        std::lock_guard lock(mutex_);
        stop_ = true;
    }
    changed_.notify_all();
    thread_.join();
}

void HeadlessRecorder::Writer::push(std::vector<std::pair<std::filesystem::path, Rgb8Image>> round) {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [this] { return queue_.size() < kMaxQueuedRounds; });
    queue_.push_back(std::move(round));
    changed_.notify_all();
}

void HeadlessRecorder::Writer::flush() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [this] { return queue_.empty() && !busy_; });
}

void HeadlessRecorder::Writer::run() {
    std::unique_lock lock(mutex_);
    for (;;) {
        changed_.wait(lock, [this] { return stop_ || !queue_.empty(); });
        if (queue_.empty()) return;  // stopping, and everything queued is written
        auto round = std::move(queue_.front());
        queue_.pop_front();
        busy_ = true;
        changed_.notify_all();  // room in the queue
        lock.unlock();
        for (const auto& [file, image] : round) {
            try {
                write_png(file, image, PngCompression::fast);  // beside the farm and the rasteriser
            } catch (const std::exception& e) {
                spdlog::warn("PNG output: {}", e.what());
            }
        }
        lock.lock();
        busy_ = false;
        changed_.notify_all();  // flush() may be waiting
    }
}

HeadlessRecorder::HeadlessRecorder(const HeadlessOutputBackend& backend, std::filesystem::path dir, int every)
    : backend_(&backend), dir_(std::move(dir)), every_(every) {
    if (every_ < 1) throw std::invalid_argument("HeadlessRecorder: every must be >= 1");
    std::filesystem::create_directories(dir_);
    writer_ = std::make_unique<Writer>();
}

std::size_t HeadlessRecorder::write_round(std::uint64_t round, std::uint64_t request_id, bool forced) {
    if (!forced && round % static_cast<std::uint64_t>(every_) != 0) return 0;
    std::vector<std::pair<std::filesystem::path, Rgb8Image>> files;
    for (std::size_t i = 0; i < backend_->outputs().size(); ++i) {
        const Rgb8Image& frame = backend_->last_frame(i);
        if (frame.size.pixel_count() == 0) continue;
        // A copy: the backend reads the next round back into the same image.
        files.emplace_back(dir_ / fmt::format("{}-{:06}-req{}.png", backend_->outputs()[i].name, round, request_id),
                           frame);
    }
    const std::size_t queued = files.size();
    if (queued > 0) writer_->push(std::move(files));
    return queued;
}

void HeadlessRecorder::flush() {
    if (writer_) writer_->flush();
}

void HeadlessRecorder::write_composite(const ScreenCalibration& screen,
                                       const std::vector<std::optional<std::size_t>>& projector_of,
                                       const std::filesystem::path& file) const {
    // composite_on_screen takes one signal image per projector of `screen`: the output that shows
    // it (in [0, 1], the projector's input signal), or black where no output does.
    std::vector<RgbFloatImage> signals;
    signals.reserve(screen.projectors.size());
    for (const auto& p : screen.projectors) signals.emplace_back(p.output, 0.0f);
    for (std::size_t i = 0; i < projector_of.size() && i < backend_->outputs().size(); ++i) {
        if (!projector_of[i]) continue;
        const Rgb8Image& frame = backend_->last_frame(i);
        RgbFloatImage& signal = signals[*projector_of[i]];
        if (!(frame.size == signal.size)) continue;  // resampled output: not the calibrated pixel grid
        for (std::size_t k = 0; k < frame.pixels.size(); ++k)
            signal.pixels[k] = static_cast<float>(frame.pixels[k]) / 255.0f;
    }
    const RgbFloatImage light = composite_on_screen(screen, signals);
    Rgb8Image out(light.size);
    for (std::size_t k = 0; k < light.pixels.size(); ++k) out.pixels[k] = srgb8_encode(light.pixels[k]);
    write_png(file, out);
}

}  // namespace mogao
