// SPDX-License-Identifier: Apache-2.0
// FrameInbox: where the link's frames are decoded for the kiosk's event loop. The link's frame
// callback (its connection thread) hands each frame to a DecodeWorker (appliance/decode/
// decode_worker.h: newest wins, decoded on the worker's thread, the last good frame kept), which
// signals an EventFd after each decode; the loop polls fd() and takes the newest decoded frame, so
// the display thread never decodes. put() returns at once, which acknowledges the frame to the farm
// (docs/kiosk.md, "The event loop").
//
// Threading: put() from any thread; take() from the loop; the wake-up from the worker's thread
// (eventfd writes are atomic). Errors: create() returns the eventfd's errno error; a failed wake-up
// or drain is logged (it only happens for a broken fd) and the frame stays in the worker.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>

#include "appliance/decode/decode_worker.h"
#include "common/event_fd.h"
#include "common/link_types.h"
#include "common/result.h"

namespace mogao {

class FrameInbox {
public:
    // Heap-allocated: the link's callback keeps a pointer to it (the slot's mutex cannot move).
    [[nodiscard]] static Result<std::unique_ptr<FrameInbox>> create();

    // Hands `frame` to the decode worker as the newest. Any thread.
    void put(LinkFrame&& frame);

    // The loop's side: resets the wake-up and takes the newest decoded frame (none when nothing
    // new) and the rejections since the last take.
    [[nodiscard]] DecodeWorker::Taken take();

    [[nodiscard]] int fd() const { return wake_.fd(); }
    // Frames dropped before they were decoded or shown (newer ones replaced them), since construction.
    [[nodiscard]] std::uint64_t replaced() const { return worker_.superseded(); }
    // Frames that failed to decode, since construction.
    [[nodiscard]] std::uint64_t rejected() const { return worker_.rejected(); }
    // Blocks until every frame put so far has been decoded or rejected (tests).
    void wait_decoded() { worker_.wait_idle(); }

private:
    explicit FrameInbox(EventFd wake);

    EventFd wake_;
    DecodeWorker worker_;  // after wake_: it signals wake_, and is stopped (joined) first
};

}  // namespace mogao
