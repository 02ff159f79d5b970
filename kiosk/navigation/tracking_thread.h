// SPDX-License-Identifier: Apache-2.0
// TrackingThread: the kiosk's navigation input when [navigation].source = "tracking". One thread
// runs camera -> TagTracker and pushes one TagSample per frame into a TagSampleQueue; the display
// loop (main thread) feeds them to its Navigator and advances it every tick (docs/kiosk.md,
// "Navigation"). The Navigator is not thread-safe and never leaves the loop's thread.
//
// Clock: samples are stamped on CLOCK_MONOTONIC (std::chrono::steady_clock), the clock the loop
// passes to Navigator::advance(). A V4L2 camera's timestamps already are (kernel or dequeue
// CLOCK_MONOTONIC). A replay's timestamps (timestamps.txt, from 0) are rebased: the first frame is
// "captured" when the thread starts, and each later frame is released at its rebased time -- the
// replay plays in real time, as a camera would (the image is read before the wait, detection after
// it, so the sample's latency is the detection's, as with a camera). Like a camera, it never
// queues: when detection falls behind, a frame whose successor is already due is skipped (counted
// in TrackingCounters::skipped), so samples stay fresh on a slow or busy machine.
//
// Errors never end the kiosk: an undecodable frame (EBADMSG) or a frame of the wrong size is
// skipped and counted; a camera timeout (ETIMEDOUT) is logged and waited out (the Navigator sees no
// samples and decelerates); any other camera error (unplugged: ENODEV) closes the camera and
// re-opens it every second until it works again or the kiosk stops. Logs are rate-limited (the
// first five, then every hundredth). The end of a replay (ENODATA, replay_end = stop or idle)
// closes the queue and ends the thread.
//
// Stop: stop() (or the destructor) sets a flag, wakes any wait and joins. A V4L2 capture blocks at
// most its timeout (1 s here), so stopping takes at most about a second.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "appliance/tracker/tag_tracker.h"
#include "drivers/camera/frame_source.h"
#include "kiosk/config/kiosk_config.h"
#include "kiosk/navigation/tag_sample_queue.h"

namespace mogao {

// CLOCK_MONOTONIC now, ns (steady_clock).
[[nodiscard]] std::int64_t monotonic_ns();

struct TrackingCounters {
    std::uint64_t frames = 0;        // tracked
    std::uint64_t skipped = 0;       // replay frames dropped because a newer one was already due
    std::uint64_t visible = 0;       // with the tag
    std::uint64_t ambiguous = 0;     // IPPE choice by continuity
    std::uint64_t frame_errors = 0;  // skipped: undecodable or wrong size
    std::uint64_t timeouts = 0;      // ETIMEDOUT from the camera
    std::uint64_t reopens = 0;       // camera re-opened after an error
    bool ended = false;              // the replay ran out
};

class TrackingThread {
public:
    // Opens the camera and starts the thread. Throws std::runtime_error naming the camera
    // ([navigation].camera) when it cannot be opened, std::invalid_argument for bad tracker settings.
    TrackingThread(const TrackingConfig& config, TagSampleQueue& queue);
    ~TrackingThread();
    TrackingThread(const TrackingThread&) = delete;
    TrackingThread& operator=(const TrackingThread&) = delete;

    // Asks the thread to stop and joins it. Idempotent.
    void stop();

    [[nodiscard]] TrackingCounters counters() const;
    [[nodiscard]] const std::string& description() const { return description_; }

private:
    void run();
    // After a camera error: waits a second and tries to open the camera again. False when the thread was stopped.
    bool reopen_source();
    // A failed next_frame(): counts and logs it (the end of a replay closes the queue, a failed camera is closed to be
    // re-opened). False when the thread must end (the replay ended).
    bool on_frame_error(int code, const std::string& message);
    // Waits until `deadline_ns` (CLOCK_MONOTONIC) or stop(); false when stopped.
    bool wait_until(std::int64_t deadline_ns);
    void count(std::uint64_t TrackingCounters::*field);

    CameraSourceSpec spec_;
    TagTracker tracker_;
    TagSampleQueue& queue_;
    std::unique_ptr<FrameSource> source_;
    std::string description_;

    mutable std::mutex mutex_;  // guards counters_ and stop_ (with wake_)
    std::condition_variable wake_;
    bool stop_ = false;
    TrackingCounters counters_;
    std::thread thread_;  // last: started when everything above exists
};

}  // namespace mogao
