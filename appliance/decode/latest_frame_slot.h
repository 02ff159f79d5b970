// SPDX-License-Identifier: Apache-2.0
// LatestFrameSlot: hands frames from the link's connection thread to the kiosk's event loop.
// One slot, newest wins: put() replaces a frame the loop has not taken yet (that frame is dropped
// and counted), so a slow display always shows the newest frame instead of working through a
// queue of stale ones. Thread-safe: put() from the gRPC thread, take() from the loop; the mutex is
// held only to move a LinkFrame (a vector of JPEG bytes: no copy, no decoding under the lock).
//
// The slot does not wake the loop itself: the caller signals an EventFd after put().
#pragma once

#include <cstdint>
#include <mutex>
#include <optional>

#include "common/link_types.h"

namespace mogao {

class LatestFrameSlot {
public:
    // Stores `frame` as the newest. Returns true when it replaced a frame not yet taken.
    bool put(LinkFrame frame);

    // The newest frame, emptying the slot; nullopt when there is none.
    [[nodiscard]] std::optional<LinkFrame> take();

    // Frames replaced before they were taken, since construction.
    [[nodiscard]] std::uint64_t replaced() const;
    // Frames put, since construction.
    [[nodiscard]] std::uint64_t stored() const;

private:
    mutable std::mutex mutex_;
    std::optional<LinkFrame> frame_;
    std::uint64_t replaced_ = 0;
    std::uint64_t stored_ = 0;
};

}  // namespace mogao
