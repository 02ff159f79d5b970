// SPDX-License-Identifier: Apache-2.0
#include "appliance/decode/decode_worker.h"

#include <utility>

namespace mogao {

DecodeWorker::DecodeWorker(std::function<void()> on_decoded)
    : on_decoded_(std::move(on_decoded)), thread_([this] { run(); }) {}

DecodeWorker::~DecodeWorker() {
    {
        const std::lock_guard lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
}

void DecodeWorker::put(LinkFrame frame) {
    {
        const std::lock_guard lock(mutex_);
        if (input_) ++superseded_;
        input_ = std::move(frame);
    }
    wake_.notify_one();
}

DecodeWorker::Taken DecodeWorker::take() {
    const std::lock_guard lock(mutex_);
    Taken taken{std::move(output_), std::move(rejections_)};
    output_.reset();
    rejections_.clear();
    return taken;
}

std::uint64_t DecodeWorker::superseded() const {
    const std::lock_guard lock(mutex_);
    return superseded_;
}

std::uint64_t DecodeWorker::rejected() const {
    const std::lock_guard lock(mutex_);
    return rejected_;
}

void DecodeWorker::wait_idle() {
    std::unique_lock lock(mutex_);
    idle_.wait(lock, [this] { return !busy_ && !input_; });
}

void DecodeWorker::run() {
    for (;;) {
        LinkFrame frame;
        {
            std::unique_lock lock(mutex_);
            wake_.wait(lock, [this] { return stop_ || input_.has_value(); });
            if (stop_) return;
            frame = std::move(*input_);
            input_.reset();
            busy_ = true;
        }
        const std::string why = last_good_.accept(frame);  // the decode, outside the lock
        {
            const std::lock_guard lock(mutex_);
            if (why.empty()) {
                if (output_) ++superseded_;
                output_ = *last_good_.current();
            } else {
                rejections_.push_back({++rejected_, why});
                if (rejections_.size() > kMaxRejections) rejections_.erase(rejections_.begin());
            }
        }
        if (on_decoded_) on_decoded_();
        {
            // Idle only after on_decoded ran, so wait_idle() also waits for the callback.
            const std::lock_guard lock(mutex_);
            busy_ = false;
        }
        idle_.notify_all();
    }
}

}  // namespace mogao
