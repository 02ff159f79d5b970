// SPDX-License-Identifier: Apache-2.0
// Per-frame figures the farm records (stats.json) and the per-tile times it measured
// (tile-costs.json, input of bench/balance_sim — format in docs/load-balancing.md).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "common/pixel_rect.h"
#include "renderfarm/scene/scene_file.h"
#include "renderfarm/schedule/cost_map.h"

namespace mogao {

struct FrameStats {
    std::uint64_t frame = 0;
    double frame_seconds = 0.0;               // admin wall time: assign -> JPEG written
    double render_phase_seconds = 0.0;        // admin wall time from assignment sent to last rank's pixels in
    std::vector<double> rank_render_seconds;  // per render rank (index 0 = MPI rank 1)
    std::vector<double> rank_predicted_seconds;
    double balance_efficiency = 1.0;  // mean(rank_render_seconds) / max(rank_render_seconds)
    std::uint64_t rays = 0;           // every ray traced: camera, shadow, AO, bounce
    double rays_per_second = 0.0;     // rays / render_phase_seconds
    double encode_seconds = 0.0;      // TurboJPEG, full frame
    std::uint64_t jpeg_bytes = 0;
    // The frame's time budget (DispatchSettings::frame_budget_s): tiles rendered coarse after it ran
    // out, and what the render phase would have taken uncut (full_pass_seconds, rank_liveness.h;
    // = render_phase_seconds when not cut).
    std::uint64_t tiles_cut = 0;
    double full_seconds = 0.0;
};

struct RunInfo {
    std::string scene;
    std::string balancer;
    int ranks = 1;         // MPI world size
    int render_ranks = 1;  // ranks that trace (world size - 1, or 1 when the admin renders alone)
    int threads_per_rank = 1;
    ImageSize size;
    std::string camera;
    std::string path;
    int spp = 1, max_bounces = 0, ao_samples = 0, jpeg_quality = 85;
    double resolution_scale = 1.0;
    std::uint64_t seed = 1;
    SceneLoadReport scene_load;
    double scene_load_seconds = 0.0;
    double bvh_build_seconds = 0.0;
};

void write_stats_json(const std::filesystem::path& file, const RunInfo& run, const std::vector<FrameStats>& frames);

void write_tile_costs_json(const std::filesystem::path& file, ImageSize size, int cell_size,
                           const std::vector<std::vector<TileTime>>& frames);

}  // namespace mogao
