// SPDX-License-Identifier: Apache-2.0
// SignalFd: SIGINT/SIGTERM (or any set) delivered as readable data on a signalfd(2) instead of an
// asynchronous handler, so the kiosk stops cleanly from its event loop (stats written, outputs
// released in order).
//
// create() blocks the signals in the calling thread first. Threads inherit the mask of the thread
// that starts them, so create the SignalFd in main() BEFORE any other thread exists (the link's
// gRPC threads, Mesa's llvmpipe threads); otherwise the kernel may deliver the signal to a thread
// that has it unblocked and the default action kills the process.
//
// At destruction, OnDestroy::restore_mask (for a SignalFd that lives in a scope of a longer
// program, e.g. a test) consumes the set's pending signals and restores the destroying thread's
// previous mask. A program's own SignalFd uses OnDestroy::keep_blocked: the mask stays blocked
// until the process has exited, so a signal that arrives after the loop stopped (while main
// returns, static destructors and atexit handlers run, or the other threads still unwind) stays
// pending and dies with the process instead of ending it by the default action (exit status 143
// instead of 0 for a SIGTERM).
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
    enum class OnDestroy { restore_mask, keep_blocked };

    [[nodiscard]] static Result<SignalFd> create(std::initializer_list<int> signals,
                                                 OnDestroy on_destroy = OnDestroy::restore_mask);
    // Restores the mask (OnDestroy::restore_mask) unless moved from (an empty fd_ marks that: it
    // is valid exactly while this object owns the blocked set).
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
    SignalFd(UniqueFd fd, sigset_t set, sigset_t previous, OnDestroy on_destroy)
        : fd_(std::move(fd)), set_(set), previous_(previous), on_destroy_(on_destroy) {}
    UniqueFd fd_;
    sigset_t set_{};
    sigset_t previous_{};
    OnDestroy on_destroy_ = OnDestroy::restore_mask;
};

}  // namespace mogao
