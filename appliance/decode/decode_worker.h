// SPDX-License-Identifier: Apache-2.0
// DecodeWorker: decodes the link's JPEG frames on a thread of its own, so that the display loop
// never waits for a decode (a 1080p frame takes tens of milliseconds on a small CPU, a whole
// display refresh).
//
//   put()   link thread: the frame becomes the newest undecoded one (newest wins: one not yet
//           taken by the worker is dropped and counted as superseded) and the worker is woken
//   worker  decodes it through a LastGoodFrame (appliance/decode/last_good_frame.h): a frame that
//           fails is rejected with its reason and the last good frame stays current; a frame that
//           decodes becomes the newest decoded one (newest wins again: one the loop has not taken
//           yet is dropped and counted as superseded); then calls `on_decoded` (the kiosk signals
//           its eventfd)
//   take()  display loop: the newest decoded frame (nullopt when nothing new) and the rejections
//           since the last take()
// So the loop only ever shows complete frames, in increasing request order, and keeps the last
// good one whatever arrives; the work a slow loop cannot show is skipped at both hand-overs.
//
// Threading: put() from any thread, take()/wait_idle() from any thread, on_decoded on the worker's
// thread (keep it short and non-blocking). The destructor stops and joins the worker (a decode in
// progress finishes first). Errors: none of its own; rejections are returned by take().
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "appliance/decode/last_good_frame.h"
#include "common/link_types.h"

namespace mogao {

class DecodeWorker {
public:
    // Starts the worker thread. `on_decoded` runs after each frame was decoded or rejected.
    explicit DecodeWorker(std::function<void()> on_decoded);
    ~DecodeWorker();
    DecodeWorker(const DecodeWorker&) = delete;
    DecodeWorker& operator=(const DecodeWorker&) = delete;

    // Link thread: `frame` is the newest frame to decode.
    void put(LinkFrame frame);

    struct Rejection {
        std::uint64_t number = 0;  // 1 for the run's first rejected frame, 2 for the second, ...
        std::string why;           // LastGoodFrame::accept's reason
    };
    struct Taken {
        std::optional<ContentFrame> frame;  // the newest decoded frame not taken yet
        std::vector<Rejection> rejections;  // since the last take(), the latest kMaxRejections
    };
    static constexpr std::size_t kMaxRejections = 16;
    [[nodiscard]] Taken take();

    // Frames dropped before the worker decoded them or before the loop took them (running total).
    [[nodiscard]] std::uint64_t superseded() const;
    [[nodiscard]] std::uint64_t rejected() const;

    // Blocks until every frame put so far has been decoded or rejected and its on_decoded has
    // returned (tests, clean stop).
    void wait_idle();

private:
    void run();

    std::function<void()> on_decoded_;
    LastGoodFrame last_good_;  // worker thread only
    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::condition_variable idle_;
    std::optional<LinkFrame> input_;
    std::optional<ContentFrame> output_;
    std::vector<Rejection> rejections_;
    std::uint64_t superseded_ = 0;
    std::uint64_t rejected_ = 0;
    bool busy_ = false;
    bool stop_ = false;
    std::thread thread_;  // last: started once everything above exists
};

}  // namespace mogao
