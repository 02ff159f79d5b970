// SPDX-License-Identifier: Apache-2.0
// EventFd: one eventfd(2) counter, the kiosk's wake-up from other threads. The link's frame
// callback (a gRPC thread) calls signal() after it stored a frame in the LatestFrameSlot; the event
// loop polls fd() for POLLIN and calls drain(). Opened EFD_CLOEXEC | EFD_NONBLOCK.
//
// Errors (common/result.h): create() returns the errno of eventfd(2) (EMFILE, ENFILE, ENOMEM);
// signal() and drain() return EIO-style errno errors that only a closed or broken fd produces.
// signal() and drain() are safe to call from any thread at the same time (eventfd reads and writes
// are atomic in the kernel).
#pragma once

#include <cstdint>

#include "common/result.h"
#include "common/unique_fd.h"

namespace mogao {

class EventFd {
public:
    [[nodiscard]] static Result<EventFd> create();

    [[nodiscard]] int fd() const { return fd_.get(); }

    // Adds 1 to the counter (the fd becomes readable). A counter at its maximum (2^64 - 2, EAGAIN)
    // counts as success: the loop is woken either way.
    [[nodiscard]] Status signal() const;

    // Reads and resets the counter: the number of signal() calls since the last drain, 0 when
    // none (the fd was not readable).
    [[nodiscard]] Result<std::uint64_t> drain() const;

private:
    explicit EventFd(UniqueFd fd) : fd_(std::move(fd)) {}
    UniqueFd fd_;
};

}  // namespace mogao
