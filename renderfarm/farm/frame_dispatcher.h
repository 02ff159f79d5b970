// SPDX-License-Identifier: Apache-2.0
// The MPI side of one sort-first frame, both ends of it:
//  - FrameDispatcher (admin, rank 0): assigns rects with the load balancer from the stream's
//    predicted cost map, broadcasts the view, gathers sRGB8 pixels and per-tile times from the render
//    ranks, composites the frame and updates the stream's cost map from the measured times (PBT).
//  - serve_render_rank (ranks 1..N-1): the loop that answers the dispatcher until it stops.
// With one process the dispatcher traces the frame itself with a local Renderer.
//
// Only the process's main thread may call these (MPI_THREAD_FUNNELED).
// Errors: a rank's failure (its message names rank, frame and reason) is thrown as FarmError by
// render() after every rank's reply was collected, so no rank is left blocked; the caller then calls
// stop(). Bad views are rejected on the ranks by the renderer's validation (std::invalid_argument).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <stdexcept>
#include <vector>

#include "renderfarm/farm/frame_stats.h"
#include "renderfarm/farm/mpi_session.h"
#include "renderfarm/schedule/cost_map.h"
#include "renderfarm/schedule/load_balancer.h"
#include "renderfarm/trace/renderer.h"
#include "common/image.h"
#include "common/view_request.h"

namespace mogao {

struct FarmError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

struct DispatchSettings {
    std::string balancer = "pbt";  // pbt | equal | roundrobin
    int snap = 16;                 // PBT/equal split snap, pixels
    int roundrobin_tile = 32;      // round-robin tile, pixels
    int cell_size = 16;            // tile timing / cost-map cell, pixels
    int threads = 1;               // render threads per rank
    float exposure = 1.f;          // the scene's exposure (sRGB8 conversion happens on the ranks)
    ToneMap tone_map = ToneMap::clamp;  // the scene's tone map (film.h)
};

struct DispatchedFrame {
    Rgb8Image image;               // render_size(view), sRGB8
    std::vector<TileTime> tiles;   // measured per-tile times of every rank
    FrameStats stats;              // all but encode figures
};

class FrameDispatcher {
public:
    // `local` renders when the world has one process (may be null otherwise).
    FrameDispatcher(const MpiSession& mpi, DispatchSettings settings, Renderer* local);
    ~FrameDispatcher();  // stops the render ranks if stop() was not called
    FrameDispatcher(const FrameDispatcher&) = delete;
    FrameDispatcher& operator=(const FrameDispatcher&) = delete;

    // Renders one frame; `stream` keys the predicted cost map (one per camera path or appliance
    // session: consecutive frames of a stream predict each other).
    DispatchedFrame render(const ViewRequest& view, std::uint64_t stream = 0);

    // Releases the render ranks (they leave serve_render_rank). Idempotent.
    void stop();

    [[nodiscard]] int render_ranks() const;
    [[nodiscard]] int cell_size() const { return settings_.cell_size; }

private:
    bool gather(const ViewRequest& view, const Assignment& assignment, DispatchedFrame& frame);

    const MpiSession& mpi_;
    DispatchSettings settings_;
    Renderer* local_;
    std::unique_ptr<LoadBalancer> balancer_;
    std::map<std::uint64_t, CostMap> predicted_;
    bool stopped_ = false;
};

// Render ranks: answer frames until the dispatcher stops. `renderer` is null when this rank could
// not build one (then every frame is answered with `load_error`).
void serve_render_rank(Renderer* renderer, const DispatchSettings& settings, const std::string& load_error);

}  // namespace mogao
