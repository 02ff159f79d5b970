// SPDX-License-Identifier: Apache-2.0
#include "common/event_loop.h"

#include <poll.h>

#include <cerrno>

namespace mogao {

void EventLoop::watch(int fd, Handler on_readable) {
    if (fd < 0) return;
    watches_.push_back({fd, std::move(on_readable)});
}

Status EventLoop::run_once(int timeout_ms) {
    std::vector<pollfd> fds;
    fds.reserve(watches_.size());
    for (const Watch& w : watches_) fds.push_back({w.fd, POLLIN, 0});
    int n = 0;
    do {
        n = ::poll(fds.data(), fds.size(), timeout_ms);
    } while (n < 0 && errno == EINTR);
    if (n < 0) return errno_error("poll");
    for (std::size_t i = 0; i < fds.size() && !stopping_; ++i) {
        if ((fds[i].revents & (POLLIN | POLLERR | POLLHUP | POLLNVAL)) != 0) watches_[i].handler();
    }
    return {};
}

Status EventLoop::run() {
    while (!stopping_) {
        if (Status s = run_once(-1); !s) return s;
    }
    return {};
}

}  // namespace mogao
