// SPDX-License-Identifier: Apache-2.0
// EventLoop: the kiosk's single-threaded poll(2) loop. Each watched fd has a handler that runs on
// the loop's thread when the fd is readable (POLLIN; POLLERR/POLLHUP also run it, so the handler's
// read reports the problem). Everything the appliance does per frame happens in these handlers:
// no locks are needed between them, and the GL context stays on this one thread.
//
// A negative fd is ignored (the headless output backend has no event fd), as poll(2) does.
// Handlers may call stop(): run() returns without running the remaining handlers of that round.
// Errors: run() returns poll's errno error (EINTR is retried) and stops; a handler's exceptions
// propagate out of run() unchanged.
#pragma once

#include <functional>
#include <vector>

#include "common/result.h"

namespace mogao {

class EventLoop {
public:
    using Handler = std::function<void()>;

    // Watches `fd` for readability. Watching the same fd twice runs both handlers.
    void watch(int fd, Handler on_readable);

    // Ends run() after the current round of handlers.
    void stop() { stopping_ = true; }
    [[nodiscard]] bool stopping() const { return stopping_; }

    // Polls and dispatches until stop(). Returns immediately when stop() was already called.
    [[nodiscard]] Status run();

    // One poll of at most `timeout_ms` (-1: forever) and its handlers; for tests.
    [[nodiscard]] Status run_once(int timeout_ms);

private:
    struct Watch {
        int fd;
        Handler handler;
    };
    std::vector<Watch> watches_;
    bool stopping_ = false;
};

}  // namespace mogao
