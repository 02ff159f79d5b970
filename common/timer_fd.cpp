// SPDX-License-Identifier: Apache-2.0
#include "common/timer_fd.h"

#include <sys/timerfd.h>
#include <unistd.h>

#include <cerrno>
#include <string>

namespace mogao {
namespace {

timespec to_timespec(std::chrono::nanoseconds d) {
    timespec t{};
    t.tv_sec = static_cast<time_t>(d.count() / 1'000'000'000);
    t.tv_nsec = static_cast<long>(d.count() % 1'000'000'000);
    return t;
}

}  // namespace

Result<TimerFd> TimerFd::create() {
    const int fd = ::timerfd_create(CLOCK_MONOTONIC, TFD_CLOEXEC | TFD_NONBLOCK);
    if (fd < 0) return errno_error("timerfd_create");
    return TimerFd(UniqueFd(fd));
}

Status TimerFd::arm(std::chrono::nanoseconds period) const {
    if (period < std::chrono::milliseconds(1) || period > std::chrono::hours(1)) {
        return make_error(EINVAL, "timer period of " + std::to_string(period.count()) + " ns is outside [1 ms, 1 h]");
    }
    itimerspec spec{};
    spec.it_interval = to_timespec(period);
    spec.it_value = to_timespec(period);
    if (::timerfd_settime(fd_.get(), 0, &spec, nullptr) != 0) return errno_error("timerfd_settime");
    return {};
}

Status TimerFd::disarm() const {
    const itimerspec spec{};
    if (::timerfd_settime(fd_.get(), 0, &spec, nullptr) != 0) return errno_error("timerfd_settime");
    return {};
}

Result<std::uint64_t> TimerFd::drain() const {
    std::uint64_t expirations = 0;
    for (;;) {
        const ssize_t n = ::read(fd_.get(), &expirations, sizeof expirations);
        if (n == static_cast<ssize_t>(sizeof expirations)) return expirations;
        if (n < 0 && errno == EINTR) continue;
        if (n < 0 && errno == EAGAIN) return std::uint64_t{0};
        return errno_error("timerfd read");
    }
}

}  // namespace mogao
