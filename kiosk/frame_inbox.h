// SPDX-License-Identifier: Apache-2.0
// FrameInbox: where the link's frames wait for the kiosk's event loop. The link's frame callback (its
// connection thread) puts each frame into a LatestFrameSlot (newest wins: appliance/decode/
// latest_frame_slot.h) and signals an EventFd; the loop polls fd() and takes the newest frame.
// put() returns at once, which acknowledges the frame to the farm (docs/kiosk.md, "The event loop").
//
// Threading: put() from any thread (the slot has its own mutex, eventfd writes are atomic); take()
// from the loop only. Errors: create() returns the eventfd's errno error; a failed wake-up or drain
// is logged (it only happens for a broken fd) and the frame stays in the slot.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>

#include "appliance/decode/latest_frame_slot.h"
#include "common/link_types.h"
#include "common/result.h"
#include "kiosk/event_fd.h"

namespace mogao {

class FrameInbox {
public:
    // Heap-allocated: the link's callback keeps a pointer to it (the slot's mutex cannot move).
    [[nodiscard]] static Result<std::unique_ptr<FrameInbox>> create();

    // Stores `frame` as the newest and wakes the loop. Any thread.
    void put(LinkFrame&& frame);

    // The loop's side: resets the wake-up and takes the newest frame (nullopt when none).
    [[nodiscard]] std::optional<LinkFrame> take();

    [[nodiscard]] int fd() const { return wake_.fd(); }
    // Frames replaced in the slot before the loop took them, since construction.
    [[nodiscard]] std::uint64_t replaced() const { return slot_.replaced(); }

private:
    explicit FrameInbox(EventFd wake) : wake_(std::move(wake)) {}

    LatestFrameSlot slot_;
    EventFd wake_;
};

}  // namespace mogao
