// SPDX-License-Identifier: Apache-2.0
// The live farm: the admin serves appliances over the link (gRPC + mutual TLS over IPv6,
// renderfarm/link) and renders each session's newest view request on the MPI farm.
//
// Threads: gRPC calls the frame renderer from its own threads, but MPI may only be used from the
// main thread (MPI_THREAD_FUNNELED), so renderer calls are queued to the main thread
// (main_thread_queue.h: only a session's newest request waits there), which renders them one at a
// time through LiveFrames (live_frames.h: progressive refinement, frame-time target, per-session
// cost maps). With `pipeline` the JPEG is encoded on the calling gRPC thread, so the main thread
// sends the ranks the next request while the previous frame is encoded; without it the main thread
// encodes before taking the next request (the serial loop of before).
// Each request first passes the farm's request policy (request_policy.h): one over the farm's
// pixel or ray bound is degraded to fit (logged once per session and decision, counted in the stats).
// Then the frame budget (session_budget.h): a request whose appliance's frames measured too dear is
// degraded to fit `budget.frame_s`, and one that cannot fit even degraded is refused (RequestRefused:
// the link ends that session with the reason). The dispatcher cuts a frame still rendering at the
// budget (DispatchSettings::frame_budget_s, set to the same value by mogao-farm serve).
// While a frame renders, systemd's watchdog is petted about once a second (FrameDispatcher
// heartbeat), so a long frame whose ranks answer is not taken for a hang.
// Errors: a request that fails (bad view, a rank's error) fails that request only — the link logs
// it and the session goes on; a refused one ends its session; SIGINT/SIGTERM stop the service cleanly (exit 0); a
// render rank that falls silent (RankTimeout, rank_liveness.h) stops serving (exit 1, then run_farm aborts the MPI
// job).
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include "renderfarm/farm/frame_dispatcher.h"
#include "renderfarm/farm/frame_stats.h"
#include "renderfarm/farm/live_frames.h"
#include "renderfarm/farm/request_policy.h"
#include "renderfarm/farm/session_budget.h"
#include "renderfarm/farm/view_policy.h"
#include "renderfarm/link/link_server.h"
#include "renderfarm/scene/scene.h"

namespace mogao {

struct ServeOptions {
    LinkServerOptions link;
    LiveOptions live;
    RequestPolicy policy;    // bounds per request (request_policy.h)
    TimeBudget budget;       // bounds per request from measured frame times (session_budget.h), after `policy`
    ViewPolicy view_policy;  // which views may be had (view_policy.h), applied before `policy`
    // Per appliance certificate (common name), replacing view_policy for it (view_policy_file.h).
    std::map<std::string, ViewPolicy> appliance_view_policies;
    bool pipeline = true;        // encode off the main thread (see above)
    double duration_s = 0.0;     // stop after this long (tests); 0 = until SIGINT/SIGTERM
    double stats_period_s = 10;  // log the link's counters this often
    // Prometheus textfile (farm_metrics.h), rewritten about once a second; empty = none.
    std::filesystem::path metrics_file;
};

// The admin's end of the link, opened before the scene loads: appliances connect (TLS handshake,
// session) and ask while every rank loads the scene and builds its BVH, and their requests wait in
// the main-thread queue until run_serve takes them. A farm restarted over its surviving hosts so
// shows its first frame sooner: the appliances' reconnects overlap the load instead of following it.
class ServeLink {
public:
    // Listens on options.link.listen. Throws what LinkServer throws (LinkError naming the address or
    // the TLS material).
    explicit ServeLink(const ServeOptions& options);
    // Fails the requests still waiting ("the farm is stopping"), so that no gRPC handler waits for a
    // frame that never comes, then stops the server.
    ~ServeLink();
    ServeLink(const ServeLink&) = delete;
    ServeLink& operator=(const ServeLink&) = delete;

private:
    struct State;
    std::unique_ptr<State> state_;
    friend int run_serve(const ServeOptions&, ServeLink&, FrameDispatcher&, const Scene&, RunInfo&);
};

// Serves the requests that arrive on `link` until SIGINT/SIGTERM, options.duration_s or a lost rank.
int run_serve(const ServeOptions& options, ServeLink& link, FrameDispatcher& farm, const Scene& scene, RunInfo& run);

}  // namespace mogao
