// SPDX-License-Identifier: Apache-2.0
#include "common/signal_fd.h"

#include <pthread.h>
#include <sys/signalfd.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <utility>

namespace mogao {

Result<SignalFd> SignalFd::create(std::initializer_list<int> signals, OnDestroy on_destroy) {
    if (signals.size() == 0) return make_error(EINVAL, "signalfd: empty signal set");
    sigset_t set;
    sigemptyset(&set);
    for (const int s : signals) {
        if (sigaddset(&set, s) != 0) return make_error(EINVAL, "signalfd: invalid signal number " + std::to_string(s));
    }
    sigset_t previous;
    if (const int rc = ::pthread_sigmask(SIG_BLOCK, &set, &previous); rc != 0) {
        return make_error(rc, std::string("pthread_sigmask: ") + std::strerror(rc));
    }
    const int fd = ::signalfd(-1, &set, SFD_CLOEXEC | SFD_NONBLOCK);
    if (fd < 0) {
        Error error = errno_error("signalfd");
        ::pthread_sigmask(SIG_SETMASK, &previous, nullptr);
        return error;
    }
    return SignalFd(UniqueFd(fd), set, previous, on_destroy);
}

SignalFd::~SignalFd() {
    // Moved from, or the program's own SignalFd: the set stays blocked until the process has exited
    // (signal_fd.h), so a signal after this point cannot end it by its default action.
    if (!fd_.valid() || on_destroy_ == OnDestroy::keep_blocked) return;
    // Consume what is pending for the set before unblocking, so that it is not delivered then.
    const timespec zero{};
    while (::sigtimedwait(&set_, nullptr, &zero) > 0) {}
    ::pthread_sigmask(SIG_SETMASK, &previous_, nullptr);
}

Result<std::optional<int>> SignalFd::read() const {
    signalfd_siginfo info{};
    for (;;) {
        const ssize_t n = ::read(fd_.get(), &info, sizeof info);
        if (n == static_cast<ssize_t>(sizeof info)) return std::optional<int>(static_cast<int>(info.ssi_signo));
        if (n < 0 && errno == EINTR) continue;
        if (n < 0 && errno == EAGAIN) return std::optional<int>();
        return errno_error("signalfd read");
    }
}

}  // namespace mogao
