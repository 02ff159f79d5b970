// SPDX-License-Identifier: Apache-2.0
// The MPI side of one sort-first frame, both ends of it:
//  - FrameDispatcher (admin, rank 0): assigns rects with the load balancer from the stream's
//    predicted cost map, sends the view to every render rank, gathers sRGB8 pixels and per-tile times from the render
//    ranks, composites the frame and updates the stream's cost map from the measured times (PBT),
//    each rank's tile times normalised by its measured speed (schedule/rank_speed.h).
//  - serve_render_rank (ranks 1..N-1): the loop that answers the dispatcher until it stops.
// With one process the dispatcher traces the frame itself with a local Renderer.
//
// Only the process's main thread may call these (MPI_THREAD_FUNNELED).
// Errors: a rank's failure (its message names rank, frame and reason) is thrown as FarmError by
// render() after every rank's reply was collected, so no rank is left blocked; the caller then calls
// stop(). Bad views are rejected on the ranks by the renderer's validation (std::invalid_argument).
// Liveness (rank_liveness.h): while a render rank renders, its main thread reports the pass's
// progress to the admin every `rank_beat_s` (the tiles are rendered on worker threads,
// tile_pass.h TilePassControl), so a frame of any cost keeps its ranks heard. A rank that owes a
// reply and has sent nothing for `rank_deadline_s` (kAllRanksSilentFactor times it when every rank
// that owes is silent at once) (dead host, SIGSTOP, cut link; every receive
// of the reply is non-blocking under it) makes render() throw RankTimeout naming the silent ranks;
// the MPI job is then unusable (a collective is half done): broken() turns true, stop() no longer
// talks to the ranks, and the process must end the job with MPI_Abort so that the service restarts
// (run_farm does this; docs/services.md).
// Time budget: a frame still rendering `frame_budget_s` after it was sent is cut: the admin tells
// the ranks that still owe a reply, and they render their remaining tiles coarse (one traced
// pixel per `cut_block`^2 block, TilePassControl), so one dear frame holds the farm for about the
// budget, not for its full cost; FrameStats::tiles_cut and ::full_seconds say so.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/image.h"
#include "common/view_request.h"
#include "renderfarm/denoise/guide_pass.h"
#include "renderfarm/farm/frame_stats.h"
#include "renderfarm/farm/mpi_session.h"
#include "renderfarm/farm/rank_liveness.h"
#include "renderfarm/farm/tile_pass.h"
#include "renderfarm/schedule/cost_map.h"
#include "renderfarm/schedule/load_balancer.h"
#include "renderfarm/schedule/rank_speed.h"
#include "renderfarm/trace/guide_buffers.h"
#include "renderfarm/trace/renderer.h"

namespace mogao {

struct FarmError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// A render rank did not reply in time; the MPI job must be aborted (see above).
struct RankTimeout : FarmError {
    using FarmError::FarmError;
};

struct DispatchSettings {
    std::string balancer = "pbt";       // pbt | equal | roundrobin
    int snap = 16;                      // PBT/equal split snap, pixels
    int roundrobin_tile = 32;           // round-robin tile, pixels
    int cell_size = 16;                 // tile timing / cost-map cell, pixels
    int threads = 0;                    // render threads per rank; 0 = automatic (render_threads.h)
    float exposure = 1.f;               // the scene's exposure (sRGB8 conversion happens on the ranks)
    ToneMap tone_map = ToneMap::clamp;  // the scene's tone map (film.h)
    // Feed the PBT with tile times x the rank's speed (its share of a core) instead of wall time.
    bool normalise_rank_speed = true;
    std::size_t max_streams = 64;  // cost maps kept; the least recently used goes beyond it
    // Seconds a render rank that owes a reply may stay silent (no progress report, no reply) before
    // it is taken for lost (rank_liveness.h: longer when all are silent at once); 0 = never.
    double rank_deadline_s = 2.0;
    double rank_beat_s = 0.1;  // how often a rendering rank reports its progress, seconds (> 0)
    // Seconds after which a frame's remaining tiles are rendered coarse (see above); 0 = never.
    double frame_budget_s = 0.0;
    int cut_block = 8;  // pixels per side of a coarse block after a cut (>= 1)
};

struct DispatchedFrame {
    Rgb8Image image;              // render_size(view), sRGB8 (PackedPixels::srgb8 frames)
    RgbFloatImage radiance;       // render_size(view), linear (PackedPixels::linear, ::linear_guided frames)
    GuideBuffers guides;          // render_size(view), the denoiser's guides (PackedPixels::linear_guided)
    std::vector<TileTime> tiles;  // measured per-tile times of every rank
    FrameStats stats;             // all but encode figures
};

class FrameDispatcher {
public:
    // `local` renders when the world has one process (may be null otherwise); `local_guides` (a
    // GuidePass on local's geometry, may be null: the renderer's own first hits, tile_pass.h) traces
    // the guides of PackedPixels::linear_guided frames.
    FrameDispatcher(const MpiSession& mpi, DispatchSettings settings, Renderer* local,
                    GuidePass* local_guides = nullptr);
    ~FrameDispatcher();  // stops the render ranks if stop() was not called
    FrameDispatcher(const FrameDispatcher&) = delete;
    FrameDispatcher& operator=(const FrameDispatcher&) = delete;

    // Renders one frame; `stream` keys the predicted cost map (one per camera path or appliance
    // session: consecutive frames of a stream predict each other; a frame of another size than the
    // stream's last one predicts from its map resampled, CostMap::resampled). `format` picks what
    // the ranks send: sRGB8 pixels (DispatchedFrame::image), linear radiance (::radiance), or linear
    // radiance and the denoiser's guides (::radiance, ::guides; FarmError from a one-process farm
    // without a guide pass).
    DispatchedFrame render(const ViewRequest& view, std::uint64_t stream = 0,
                           PackedPixels format = PackedPixels::srgb8);

    // Releases the render ranks (they leave serve_render_rank). Idempotent.
    void stop();

    [[nodiscard]] int render_ranks() const;
    [[nodiscard]] int cell_size() const { return settings_.cell_size; }
    [[nodiscard]] const DispatchSettings& settings() const { return settings_; }
    // Called about once a second while render() waits for the ranks (serve pets systemd's
    // watchdog from it, so a long frame whose ranks answer is not mistaken for a hang).
    void set_heartbeat(std::function<void()> heartbeat) { heartbeat_ = std::move(heartbeat); }
    // True after a RankTimeout: the MPI job must be aborted.
    [[nodiscard]] bool broken() const { return broken_; }
    // The ranks that RankTimeout named silent (empty before one).
    [[nodiscard]] const std::vector<int>& lost_ranks() const { return lost_ranks_; }
    // Benchmarks compare raw and speed-normalised tile times in one run.
    void set_normalise_rank_speed(bool on) { settings_.normalise_rank_speed = on; }

private:
    bool gather(const ViewRequest& view, const Assignment& assignment, PackedPixels format, DispatchedFrame& frame,
                std::vector<TileTime>& normalised);
    CostMap& stream_map(std::uint64_t stream, ImageSize size);
    struct Watch;  // one frame's liveness and budget (frame_dispatcher.cpp)
    // Polls `done` under the frame's liveness; `transfer_from` > 0: that rank's reply is transferring, so it alone
    // is judged (the others that finished wait in their own sends, silent).
    template <typename Done>
    void poll_until(Watch& watch, const Done& done, const char* phase, int transfer_from = 0);
    int probe_reply(Watch& watch);
    void drain_progress(Watch& watch);
    void send_cuts(Watch& watch);
    [[noreturn]] void lost(const Watch& watch, const std::vector<int>& ranks, const char* phase);
    void gather_local(const ViewRequest& view, const Assignment& assignment, PackedPixels format,
                      DispatchedFrame& frame, std::vector<TileTime>& normalised);
    void add_tiles(int rank_index, const std::vector<TileTime>& tiles, double cpu, double wall,
                   std::vector<TileTime>& normalised);

    const MpiSession& mpi_;
    DispatchSettings settings_;
    Renderer* local_;
    GuidePass* local_guides_;
    std::unique_ptr<LoadBalancer> balancer_;
    struct StreamMap {
        CostMap map;
        std::uint64_t last_used;
    };
    std::map<std::uint64_t, StreamMap> predicted_;
    std::uint64_t frames_ = 0;
    RankSpeeds speeds_;
    std::uint64_t sequence_ = 0;  // frames sent to the ranks (WireView::sequence)
    bool stopped_ = false;
    bool broken_ = false;
    std::vector<int> lost_ranks_;
    std::function<void()> heartbeat_;
};

// Render ranks: answer frames until the dispatcher stops. `renderer` is null when this rank could
// not build one (then every frame is answered with `load_error`). `guides` (a GuidePass on the
// renderer's geometry) traces the guides of PackedPixels::linear_guided frames; null: the
// renderer's own first hits are the guides (tile_pass.h).
void serve_render_rank(Renderer* renderer, const DispatchSettings& settings, const std::string& load_error,
                       GuidePass* guides = nullptr);

}  // namespace mogao
