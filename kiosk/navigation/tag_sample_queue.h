// SPDX-License-Identifier: Apache-2.0
// TagSampleQueue: hands the tracking thread's tag samples to the kiosk's display loop.
//
// A bounded FIFO, not "newest wins": the Navigator's One Euro filters and flip gate want every
// sample in capture order (a skipped sample is a gap in the filter's input, and the gate compares
// each sample with the previous one). The display loop drains it every tick (30 Hz against a 30 Hz
// camera: one sample per tick, two now and then), so it holds a few samples at most; the bound
// (256, ~8 s at 30 Hz) only matters when the loop stalls, and then the OLDEST samples are dropped
// and counted -- the navigator then sees the newest samples, as after a dropped camera frame.
//
// close() marks the end of the stream (a replay ran out); take_all() reports it only together with
// the last samples, so the loop never stops before it has observed them.
//
// Thread-safe: push()/close() from the tracking thread, take_all() from the loop; the mutex is
// held only to move a few TagSamples.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <vector>

#include "appliance/navigation/navigator.h"

namespace mogao {

class TagSampleQueue {
public:
    explicit TagSampleQueue(std::size_t capacity = 256);  // capacity >= 1

    // Appends `sample`; when full, drops the oldest first. Returns false when one was dropped.
    bool push(const TagSample& sample);

    // No more samples will come (pushes after close() are ignored).
    void close();

    struct Batch {
        std::vector<TagSample> samples;  // in push order
        bool closed = false;             // closed and nothing left after these
    };
    // Every queued sample, oldest first, emptying the queue.
    [[nodiscard]] Batch take_all();

    [[nodiscard]] std::uint64_t pushed() const;   // since construction
    [[nodiscard]] std::uint64_t dropped() const;  // oldest dropped because the queue was full

private:
    mutable std::mutex mutex_;
    std::size_t capacity_;
    std::deque<TagSample> samples_;
    bool closed_ = false;
    std::uint64_t pushed_ = 0;
    std::uint64_t dropped_ = 0;
};

}  // namespace mogao
