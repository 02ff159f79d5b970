// SPDX-License-Identifier: Apache-2.0
// TimerFd: one periodic timerfd(2) on CLOCK_MONOTONIC, the kiosk's display/request tick (one view
// request per tick; outputs repainted when no new frame came since the last tick). Opened
// TFD_CLOEXEC | TFD_NONBLOCK. CLOCK_MONOTONIC: a wall-clock step (NTP on boot) never bunches or
// skips ticks.
//
// Errors (common/result.h): create() returns the errno of timerfd_create(2); arm() EINVAL for a
// period outside [1 ms, 1 h]; drain() an errno error only for a broken fd.
#pragma once

#include <chrono>
#include <cstdint>

#include "common/result.h"
#include "common/unique_fd.h"

namespace mogao {

class TimerFd {
public:
    [[nodiscard]] static Result<TimerFd> create();

    [[nodiscard]] int fd() const { return fd_.get(); }

    // Fires every `period`, the first time one period from now. Re-arming replaces the schedule.
    [[nodiscard]] Status arm(std::chrono::nanoseconds period) const;

    // Stops the timer (pending expirations are kept until drained).
    [[nodiscard]] Status disarm() const;

    // Expirations since the last drain (more than 1 when the loop was late), 0 when none.
    [[nodiscard]] Result<std::uint64_t> drain() const;

private:
    explicit TimerFd(UniqueFd fd) : fd_(std::move(fd)) {}
    UniqueFd fd_;
};

}  // namespace mogao
