// SPDX-License-Identifier: Apache-2.0
// SignalFd: SIGINT/SIGTERM (or any set) delivered as readable data on a signalfd(2) instead of an
// asynchronous handler, so the kiosk stops cleanly from its event loop (stats written, outputs
// released in order).
//
// create() blocks the signals in the calling thread first. Threads inherit the mask of the thread
// that starts them, so create the SignalFd in main() BEFORE any other thread exists (the link's
// gRPC threads, Mesa's llvmpipe threads); otherwise the kernel may deliver the signal to a thread
// that has it unblocked and the default action kills the process. The destructor restores the
// previous mask of the destroying thread after consuming the set's pending signals (so a SIGTERM
// that arrived during shutdown does not kill the process on the way out).
//
// Errors (common/result.h): create() EINVAL for an empty set or an invalid signal number, or the
// errno of pthread_sigmask/signalfd; read() an errno error for a broken fd.
#pragma once

#include <csignal>
#include <initializer_list>
#include <optional>

#include "common/result.h"
#include "common/unique_fd.h"

namespace mogao {

class SignalFd {
public:
    [[nodiscard]] static Result<SignalFd> create(std::initializer_list<int> signals);
    // Restores the mask unless moved from (an empty fd_ marks that: it is valid exactly while this
    // object owns the blocked set).
    ~SignalFd();
    SignalFd(SignalFd&&) noexcept = default;
    // Not assignable: replacing a live SignalFd would have to restore its mask first, and no caller
    // needs that.
    SignalFd& operator=(SignalFd&&) = delete;
    SignalFd(const SignalFd&) = delete;
    SignalFd& operator=(const SignalFd&) = delete;

    [[nodiscard]] int fd() const { return fd_.get(); }

    // The next pending signal number, or nullopt when none is pending.
    [[nodiscard]] Result<std::optional<int>> read() const;

private:
    SignalFd(UniqueFd fd, sigset_t set, sigset_t previous) : fd_(std::move(fd)), set_(set), previous_(previous) {}
    UniqueFd fd_;
    sigset_t set_{};
    sigset_t previous_{};
};

}  // namespace mogao
