// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/serve.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <optional>
#include <string>

#include <spdlog/spdlog.h>

#include "common/jpeg_codec.h"
#include "common/memory_release.h"
#include "common/program_cli.h"
#include "common/service_notify.h"
#include "renderfarm/farm/farm_metrics.h"
#include "renderfarm/farm/log_throttle.h"
#include "renderfarm/farm/main_thread_queue.h"
#include "renderfarm/farm/policy_gate.h"
#include "renderfarm/farm/session_budget.h"

namespace mogao {
namespace {

using Clock = std::chrono::steady_clock;

std::atomic<bool> g_stop{false};
extern "C" void on_stop_signal(int) {
    g_stop = true;
    // Up 0 now: mpirun or systemd may SIGKILL the admin before its loop sees the flag.
    FarmMetricsFile::on_stop_signal();
}

// What the main thread hands back: the frame, encoded already unless pipelining.
struct ServedFrame {
    Rgb8Image image;
    int jpeg_quality = 85;
    std::int64_t render_end_ns = 0;
    std::optional<RenderedFrame> encoded;
    std::uint32_t spp = 0, bounces = 0;  // as served (LiveFrame::samples, the traced view's bounces)
};

RenderedFrame encode(const ServedFrame& frame, JpegEncoder& encoder) {
    RenderedFrame out;
    out.size = frame.image.size;
    out.render_end_ns = frame.render_end_ns;
    out.spp = frame.spp;
    out.bounces = frame.bounces;
    out.jpeg = encoder.encode(frame.image, frame.jpeg_quality);
    return out;
}

// Runs on a gRPC thread: waits for the main thread, then encodes there when pipelining.
RenderedFrame serve_request(MainThreadQueue<ServedFrame>& queue, const ViewRequest& view) {
    ServedFrame frame = queue.push(view).get();
    if (frame.encoded) return std::move(*frame.encoded);
    thread_local JpegEncoder encoder;
    return encode(frame, encoder);
}

void log_stats(const LinkServer& server, const MainThreadQueue<ServedFrame>& queue, std::uint64_t degraded,
               const MemoryRelease& memory_release) {
    const LinkServerStats s = server.stats();
    spdlog::info(
        "link: {} sessions active, {} frames sent, {} requests ({} dropped as stale, {} superseded in the "
        "farm's queue, {} invalid, {} changed by the view or request policy), {} MB; longest memory release {:.1f} ms",
        s.sessions_active, s.frames_sent, s.requests_received, s.requests_dropped, queue.superseded(),
        s.requests_invalid, degraded, static_cast<double>(s.jpeg_bytes_sent) / 1e6, memory_release.max_ms());
}

// The frame budget across frames (session_budget.h): degrades a request to its appliance's measured
// rate, learns the rate from each rendered frame, and logs degraded requests and frames cut at the
// budget through a LogThrottle (a session's first of each at once, then about one line a minute).
class BudgetGate {
public:
    BudgetGate(const Scene& scene, TimeBudget budget) : budgets_(budget, LightCounts::of(scene)) {}

    // Throws RequestRefused for what the farm cannot render within the budget.
    ViewRequest apply(const ViewRequest& view, const std::string& who, double share_s) {
        const BudgetDecision d = budgets_.apply(view, who, share_s);
        if (!d.degraded) return d.view;
        ++degraded_;
        if (const LogThrottle::Verdict t = log_.allow("degraded:" + std::to_string(view.session), log_clock_s());
            t.write)
            spdlog::warn("session {} ({}): degraded to {} of {:.3g} s (estimated {:.2f} s at its measured rate): {}{}",
                         view.session, who,
                         d.limit_s < budgets_.budget().frame_s ? "its share of the farm" : "the frame budget",
                         d.limit_s, d.predicted_s, d.changes, held_back_note(t.held_back));
        return d.view;
    }
    void observe(const std::string& who, const LiveFrame& frame) {
        if (!frame.rendered_now) return;
        if (frame.stats.tiles_cut > 0) {
            ++cut_;
            if (const LogThrottle::Verdict t =
                    log_.allow("cut:" + std::to_string(frame.rendered.session), log_clock_s());
                t.write)
                spdlog::warn(
                    "session {} ({}): frame {} cut at the frame budget of {} s: {} tiles rendered coarse (uncut "
                    "about {:.1f} s){}",
                    frame.rendered.session, who, frame.rendered.frame_id, budgets_.budget().frame_s,
                    frame.stats.tiles_cut, frame.stats.full_seconds, held_back_note(t.held_back));
        }
        budgets_.observe(who, frame.rendered, frame.stats.full_seconds);
    }
    [[nodiscard]] std::uint64_t degraded() const { return degraded_; }
    [[nodiscard]] std::uint64_t cut() const { return cut_; }

private:
    SessionBudgets budgets_;
    LogThrottle log_;
    std::uint64_t degraded_ = 0, cut_ = 0;
};

// SIGINT and SIGTERM end the serving loop (g_stop) instead of the process: the link is closed and the ranks freed.
void install_stop_handlers() {
    struct sigaction action {};
    action.sa_handler = on_stop_signal;
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
}

void log_serving(const ServeOptions& options, const RunInfo& run, const std::string& endpoint) {
    spdlog::info(
        "serving {} ({} render ranks, {}) on {}; progressive {}, frame-time target {}, {} cost maps, "
        "pipeline {}",
        run.scene, run.render_ranks, run.balancer, endpoint, options.live.progressive ? "on" : "off",
        options.live.frame_time_s > 0 ? std::to_string(options.live.frame_time_s * 1e3) + " ms" : "off",
        options.live.per_session_maps ? "per-session" : "shared", options.pipeline ? "on" : "off");
}

// The scene's animated lights, if any, for LiveFrames to follow (the scene outlives it).
LiveOptions with_lighting(LiveOptions live, const Scene& scene) {
    if (!scene.animated_lights.empty())
        live.lighting = [&scene](double time_s) { return lighting_state(scene, time_s); };
    return live;
}

LinkServerOptions link_options(const ServeOptions& options) {
    LinkServerOptions link = options.link;
    // Pipelining needs a second call in flight (another session's) while one frame is encoded; each
    // session still has at most one, and the queue serialises them onto the main thread.
    if (options.pipeline) link.render_threads = std::clamp(link.max_sessions, std::max(2, link.render_threads), 64);
    return link;
}

}  // namespace

// Declared in this order so that the server, whose handlers hold the queue, goes first.
struct ServeLink::State {
    MainThreadQueue<ServedFrame> queue;
    LinkServer server;
    explicit State(const ServeOptions& options)
        : server(link_options(options), [this](const ViewRequest& view) { return serve_request(queue, view); }) {}
};

ServeLink::ServeLink(const ServeOptions& options) : state_(std::make_unique<State>(options)) {}

ServeLink::~ServeLink() {
    state_->queue.close();
    state_->server.stop();
}

int run_serve(const ServeOptions& options, ServeLink& link, FrameDispatcher& farm, const Scene& scene, RunInfo& run) {
    install_stop_handlers();
    MainThreadQueue<ServedFrame>& queue = link.state_->queue;
    LinkServer& server = link.state_->server;
    PolicyGate policy(scene, options.policy, ViewPolicies{options.view_policy, options.appliance_view_policies});
    BudgetGate budget(scene, options.budget);
    LiveFrames live(farm, with_lighting(options.live, scene));
    log_serving(options, run, server.endpoint().to_string());
    ServiceNotifier notifier;
    notifier.ready();
    farm.set_heartbeat([&notifier] { notifier.watchdog(); });  // a long frame is not a hang

    JpegEncoder encoder;
    FarmMetrics metrics(cli::version());
    FarmMetricsFile metrics_file(options.metrics_file);  // up 0 on every way out it can see
    const auto counters = [&](bool up) {
        return FarmCounters{up, server.stats(), queue.superseded(), policy.changed(), run.render_ranks};
    };
    map_large_blocks();            // large buffers map instead of growing the heap
    MemoryRelease memory_release;  // months of service: freed frame buffers go back (common/memory_release.h)
    const auto start = Clock::now();
    auto last_stats = start;
    auto last_metrics = start - std::chrono::seconds(1);
    const auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
    while (!g_stop && (options.duration_s <= 0 || elapsed() < options.duration_s)) {
        notifier.watchdog();
        memory_release.tick();
        if (std::chrono::duration<double>(Clock::now() - last_stats).count() >= options.stats_period_s) {
            log_stats(server, queue, policy.changed(), memory_release);
            last_stats = Clock::now();
        }
        if (Clock::now() - last_metrics >= std::chrono::seconds(1)) {
            metrics_file.update(metrics, counters(true));
            last_metrics = Clock::now();
        }
        std::optional<MainThreadQueue<ServedFrame>::Job> job = queue.next(std::chrono::milliseconds(100));
        if (!job) continue;
        // Late binding: the call waited in the queue while other sessions' frames were rendered; the
        // frame shows the newest view its session has asked for since (link_server.h).
        if (auto newer = server.take_newer_request(job->view.session)) job->view = std::move(*newer);
        try {
            const std::string who = server.appliance_of(job->view.session);
            const std::string key = who.empty() ? "session " + std::to_string(job->view.session) : who;
            const double share_s = live.frame_share_seconds(job->view.session);
            LiveFrame frame = live.render(budget.apply(policy.apply(job->view, who), key, share_s));
            budget.observe(key, frame);
            metrics.observe_frame(frame.stats, frame.seconds, double(realtime_ns()) * 1e-9, who);
            ServedFrame out{std::move(frame.image),
                            job->view.quality.jpeg_quality,
                            realtime_ns(),
                            std::nullopt,
                            static_cast<std::uint32_t>(std::max(frame.samples, 0)),
                            static_cast<std::uint32_t>(std::max(frame.rendered.quality.max_bounces, 0))};
            if (!options.pipeline) out.encoded = encode(out, encoder);
            job->result.set_value(std::move(out));
        } catch (const RankTimeout& e) {
            // A render rank is gone: no later frame can be rendered by this MPI job.
            spdlog::critical("{}", e.what());
            job->result.set_exception(std::current_exception());
            break;
        } catch (...) {
            // One bad request fails alone: the link reports it to its session and goes on.
            job->result.set_exception(std::current_exception());
        }
    }
    const bool lost_rank = farm.broken();
    spdlog::info("frame budget: {} requests degraded to it, {} frames cut at it", budget.degraded(), budget.cut());
    metrics_file.update(metrics, counters(false));
    notifier.stopping();
    spdlog::info("stopping: {}", lost_rank ? "a render rank was lost" : g_stop ? "signal" : "duration reached");
    queue.close();
    server.stop();
    farm.stop();
    return lost_rank ? 1 : 0;
}

}  // namespace mogao
