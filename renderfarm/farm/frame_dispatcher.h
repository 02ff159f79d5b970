// SPDX-License-Identifier: Apache-2.0
// The MPI side of one sort-first frame, both ends of it:
//  - FrameDispatcher (admin, rank 0): assigns rects with the load balancer from the stream's
//    predicted cost map, broadcasts the view, gathers sRGB8 pixels and per-tile times from the render
//    ranks, composites the frame and updates the stream's cost map from the measured times (PBT),
//    each rank's tile times normalised by its measured speed (schedule/rank_speed.h).
//  - serve_render_rank (ranks 1..N-1): the loop that answers the dispatcher until it stops.
// With one process the dispatcher traces the frame itself with a local Renderer.
//
// Only the process's main thread may call these (MPI_THREAD_FUNNELED).
// Errors: a rank's failure (its message names rank, frame and reason) is thrown as FarmError by
// render() after every rank's reply was collected, so no rank is left blocked; the caller then calls
// stop(). Bad views are rejected on the ranks by the renderer's validation (std::invalid_argument).
// A rank that does not reply within the frame's deadline (frame_deadline.h: a multiple of the
// frame's expected time from recent frames, between `rank_deadline_min_s` and `rank_deadline_s`;
// dead host, SIGSTOP, cut link; every receive of the reply is non-blocking under it) makes render()
// throw RankTimeout naming the silent ranks; the MPI job is then unusable (a collective is half
// done): broken() turns true, stop() no longer talks to the ranks, and the process must end the
// job with MPI_Abort so that the service restarts (run_farm does this; docs/services.md).
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
#include "renderfarm/denoise/guide_buffers.h"
#include "renderfarm/denoise/guide_pass.h"
#include "renderfarm/farm/frame_deadline.h"
#include "renderfarm/farm/frame_stats.h"
#include "renderfarm/farm/mpi_session.h"
#include "renderfarm/farm/tile_pass.h"
#include "renderfarm/schedule/cost_map.h"
#include "renderfarm/schedule/load_balancer.h"
#include "renderfarm/schedule/rank_speed.h"
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
    std::string balancer = "pbt";  // pbt | equal | roundrobin
    int snap = 16;                 // PBT/equal split snap, pixels
    int roundrobin_tile = 32;      // round-robin tile, pixels
    int cell_size = 16;            // tile timing / cost-map cell, pixels
    int threads = 1;               // render threads per rank
    float exposure = 1.f;          // the scene's exposure (sRGB8 conversion happens on the ranks)
    ToneMap tone_map = ToneMap::clamp;  // the scene's tone map (film.h)
    // Feed the PBT with tile times x the rank's speed (its share of a core) instead of wall time.
    bool normalise_rank_speed = true;
    std::size_t max_streams = 64;  // cost maps kept; the least recently used goes beyond it
    // Seconds from sending a frame to the ranks until the last reply (frame_deadline.h): at most
    // rank_deadline_s (0 = wait forever), rank_deadline_factor x the frame's expected time, at least
    // rank_deadline_min_s. Factor 0: always rank_deadline_s.
    double rank_deadline_s = 30.0;
    double rank_deadline_min_s = 2.0;
    double rank_deadline_factor = 4.0;
};

struct DispatchedFrame {
    Rgb8Image image;               // render_size(view), sRGB8 (PackedPixels::srgb8 frames)
    RgbFloatImage radiance;        // render_size(view), linear (PackedPixels::linear, ::linear_guided frames)
    GuideBuffers guides;           // render_size(view), the denoiser's guides (PackedPixels::linear_guided)
    std::vector<TileTime> tiles;   // measured per-tile times of every rank
    FrameStats stats;              // all but encode figures
};

class FrameDispatcher {
public:
    // `local` renders when the world has one process (may be null otherwise); `local_guides` (a
    // GuidePass on local's geometry, may be null) traces its guides for PackedPixels::linear_guided.
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
    // watchdog from it, so a long frame within the deadline is not mistaken for a hang).
    void set_heartbeat(std::function<void()> heartbeat) { heartbeat_ = std::move(heartbeat); }
    // True after a RankTimeout: the MPI job must be aborted.
    [[nodiscard]] bool broken() const { return broken_; }
    // Benchmarks compare raw and speed-normalised tile times in one run.
    void set_normalise_rank_speed(bool on) { settings_.normalise_rank_speed = on; }

private:
    bool gather(const ViewRequest& view, const Assignment& assignment, PackedPixels format, DispatchedFrame& frame,
                std::vector<TileTime>& normalised);
    CostMap& stream_map(std::uint64_t stream, ImageSize size);
    template <typename Done>
    void poll_until(std::chrono::steady_clock::time_point deadline, const Done& done, const std::string& who,
                    std::uint64_t frame_id);
    int probe_reply_until(std::chrono::steady_clock::time_point deadline, const std::vector<bool>& replied,
                          std::uint64_t frame_id);

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
    FrameDeadline deadline_;
    double frame_deadline_s_ = 0.0;  // the deadline of the frame being gathered, for messages
    bool stopped_ = false;
    bool broken_ = false;
    std::function<void()> heartbeat_;
};

// Render ranks: answer frames until the dispatcher stops. `renderer` is null when this rank could
// not build one (then every frame is answered with `load_error`). `guides` (a GuidePass on the
// renderer's geometry) answers PackedPixels::linear_guided frames; null: such frames fail.
void serve_render_rank(Renderer* renderer, const DispatchSettings& settings, const std::string& load_error,
                       GuidePass* guides = nullptr);

}  // namespace mogao
