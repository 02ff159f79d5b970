// SPDX-License-Identifier: Apache-2.0
// Hands renderer calls from the link's gRPC threads to the farm's main thread (the only one that
// may use MPI, MPI_THREAD_FUNNELED) and the results back.
//
// Supersede: only the newest request of a session (ViewRequest::session) waits in the queue. A
// request that arrives while an older one of the same session is still queued takes its place, and
// the older one is never rendered: its caller gets SupersededError at once. (The link server already
// keeps one pending request per session, so this is the farm's own guarantee, whatever the link's
// render_threads.) Sessions are served in arrival order of their newest request.
//
// Errors: submit() throws SupersededError, the renderer's exception, or std::runtime_error("the farm
// is stopping") after close().
#pragma once

#include <chrono>
#include <condition_variable>
#include <deque>
#include <future>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>

#include "common/view_request.h"

namespace mogao {

struct SupersededError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

template <typename Result>
class MainThreadQueue {
public:
    struct Job {
        ViewRequest view;
        std::promise<Result> result;
    };

    // gRPC threads: queues `view` and returns the future of its result.
    std::future<Result> push(const ViewRequest& view) {
        std::future<Result> done;
        std::optional<Job> replaced;
        {
            const std::lock_guard lock(mutex_);
            if (closed_) throw std::runtime_error("the farm is stopping");
            for (auto it = jobs_.begin(); it != jobs_.end(); ++it) {
                if (it->view.session == view.session) {
                    replaced = std::move(*it);
                    jobs_.erase(it);
                    ++superseded_;
                    break;
                }
            }
            jobs_.push_back({view, {}});
            done = jobs_.back().result.get_future();
        }
        if (replaced) {
            replaced->result.set_exception(
                std::make_exception_ptr(SupersededError("request " + std::to_string(replaced->view.frame_id) +
                                                        " superseded by " + std::to_string(view.frame_id))));
        }
        ready_.notify_one();
        return done;
    }

    // Main thread: the next job, or nothing after `wait` or once closed.
    std::optional<Job> next(std::chrono::milliseconds wait) {
        std::unique_lock lock(mutex_);
        ready_.wait_for(lock, wait, [&] { return !jobs_.empty() || closed_; });
        if (jobs_.empty()) return std::nullopt;
        Job job = std::move(jobs_.front());
        jobs_.pop_front();
        return job;
    }

    // Refuses new jobs and fails the waiting ones, so no gRPC thread stays blocked.
    void close() {
        std::deque<Job> left;
        {
            const std::lock_guard lock(mutex_);
            closed_ = true;
            left.swap(jobs_);
        }
        for (Job& job : left)
            job.result.set_exception(std::make_exception_ptr(std::runtime_error("the farm is stopping")));
        ready_.notify_all();
    }

    [[nodiscard]] std::uint64_t superseded() const {
        const std::lock_guard lock(mutex_);
        return superseded_;
    }

private:
    mutable std::mutex mutex_;
    std::condition_variable ready_;
    std::deque<Job> jobs_;
    bool closed_ = false;
    std::uint64_t superseded_ = 0;
};

}  // namespace mogao
