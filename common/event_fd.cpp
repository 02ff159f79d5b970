// SPDX-License-Identifier: Apache-2.0
#include "common/event_fd.h"

#include <sys/eventfd.h>
#include <unistd.h>

#include <cerrno>

namespace mogao {

Result<EventFd> EventFd::create() {
    const int fd = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
    if (fd < 0) return errno_error("eventfd");
    return EventFd(UniqueFd(fd));
}

Status EventFd::signal() const {
    const std::uint64_t one = 1;
    for (;;) {
        const ssize_t n = ::write(fd_.get(), &one, sizeof one);
        if (n == static_cast<ssize_t>(sizeof one)) return {};
        if (n < 0 && errno == EINTR) continue;
        if (n < 0 && errno == EAGAIN) return {};  // counter saturated: still readable
        return errno_error("eventfd write");
    }
}

Result<std::uint64_t> EventFd::drain() const {
    std::uint64_t count = 0;
    for (;;) {
        const ssize_t n = ::read(fd_.get(), &count, sizeof count);
        if (n == static_cast<ssize_t>(sizeof count)) return count;
        if (n < 0 && errno == EINTR) continue;
        if (n < 0 && errno == EAGAIN) return std::uint64_t{0};
        return errno_error("eventfd read");
    }
}

}  // namespace mogao
