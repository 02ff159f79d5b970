// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/serve.h"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <deque>
#include <future>
#include <mutex>
#include <optional>

#include <spdlog/spdlog.h>

#include "common/jpeg_codec.h"
#include "common/service_notify.h"

namespace mogao {
namespace {

using Clock = std::chrono::steady_clock;

std::atomic<bool> g_stop{false};
extern "C" void on_stop_signal(int) { g_stop = true; }

// Hands renderer calls from gRPC threads to the main thread.
class MainThreadQueue {
public:
    struct Job {
        ViewRequest view;
        std::promise<RenderedFrame> result;
    };

    // Called on gRPC threads: blocks until the main thread has rendered the view.
    RenderedFrame submit(const ViewRequest& view) {
        std::future<RenderedFrame> done;
        {
            const std::lock_guard lock(mutex_);
            if (closed_) throw std::runtime_error("the farm is stopping");
            jobs_.push_back({view, {}});
            done = jobs_.back().result.get_future();
        }
        ready_.notify_one();
        return done.get();
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
        for (Job& job : left) job.result.set_exception(std::make_exception_ptr(std::runtime_error("the farm is stopping")));
        ready_.notify_all();
    }

private:
    std::mutex mutex_;
    std::condition_variable ready_;
    std::deque<Job> jobs_;
    bool closed_ = false;
};

}  // namespace

int run_serve(const ServeOptions& options, FrameDispatcher& farm, const Scene&, RunInfo& run) {
    struct sigaction action {};
    action.sa_handler = on_stop_signal;
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);

    MainThreadQueue queue;
    LinkServer server(options.link, [&queue](const ViewRequest& view) { return queue.submit(view); });
    spdlog::info("serving {} ({} render ranks, {}) on {}", run.scene, run.render_ranks, run.balancer,
                 server.endpoint().to_string());
    ServiceNotifier notifier;
    notifier.ready();

    JpegEncoder encoder;
    const auto start = Clock::now();
    auto last_stats = start;
    const auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
    while (!g_stop && (options.duration_s <= 0 || elapsed() < options.duration_s)) {
        notifier.watchdog();
        if (std::chrono::duration<double>(Clock::now() - last_stats).count() >= options.stats_period_s) {
            const LinkServerStats s = server.stats();
            spdlog::info("link: {} sessions active, {} frames sent, {} requests ({} dropped as stale, {} invalid), {} MB",
                         s.sessions_active, s.frames_sent, s.requests_received, s.requests_dropped, s.requests_invalid,
                         static_cast<double>(s.jpeg_bytes_sent) / 1e6);
            last_stats = Clock::now();
        }
        std::optional<MainThreadQueue::Job> job = queue.next(std::chrono::milliseconds(100));
        if (!job) continue;
        try {
            DispatchedFrame frame = farm.render(job->view);
            RenderedFrame out;
            out.size = frame.image.size;
            out.render_end_ns = realtime_ns();
            out.jpeg = encoder.encode(frame.image, job->view.quality.jpeg_quality);
            job->result.set_value(std::move(out));
        } catch (...) {
            // One bad request fails alone: the link reports it to its session and goes on.
            job->result.set_exception(std::current_exception());
        }
    }
    notifier.stopping();
    spdlog::info("stopping: {}", g_stop ? "signal" : "duration reached");
    queue.close();
    server.stop();
    farm.stop();
    return 0;
}

}  // namespace mogao
