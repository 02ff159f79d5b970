// SPDX-License-Identifier: Apache-2.0
#include "kiosk/navigation/tag_sample_queue.h"

#include <algorithm>

namespace mogao {

TagSampleQueue::TagSampleQueue(std::size_t capacity) : capacity_(std::max<std::size_t>(capacity, 1)) {}

bool TagSampleQueue::push(const TagSample& sample) {
    const std::lock_guard lock(mutex_);
    if (closed_) return true;
    ++pushed_;
    bool kept_all = true;
    if (samples_.size() >= capacity_) {
        samples_.pop_front();
        ++dropped_;
        kept_all = false;
    }
    samples_.push_back(sample);
    return kept_all;
}

void TagSampleQueue::close() {
    const std::lock_guard lock(mutex_);
    closed_ = true;
}

TagSampleQueue::Batch TagSampleQueue::take_all() {
    const std::lock_guard lock(mutex_);
    Batch batch;
    batch.samples.assign(samples_.begin(), samples_.end());
    samples_.clear();
    batch.closed = closed_;
    return batch;
}

std::uint64_t TagSampleQueue::pushed() const {
    const std::lock_guard lock(mutex_);
    return pushed_;
}

std::uint64_t TagSampleQueue::dropped() const {
    const std::lock_guard lock(mutex_);
    return dropped_;
}

}  // namespace mogao
