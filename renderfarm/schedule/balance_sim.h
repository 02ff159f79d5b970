// SPDX-License-Identifier: Apache-2.0
// Load-balance simulation: how well each balancer would have split a recorded frame sequence.
//
// For frame f every balancer gets the same prediction, the actual cost map of frame f-1
// (CostMap::uniform for frame 0), as the farm's schedule stage would; "pbt" splits on it, "equal"
// ignores it, "roundrobin" deals tiles. The assignment is then scored with balance_efficiency()
// against frame f's actual map. The mean/min efficiency per balancer and rank count, and the
// ratios pbt/equal and pbt/roundrobin of the means, all come from the same run.
// Usage and input format: docs/load-balancing.md (bench/balance_sim.cpp, tile-costs.json).
#pragma once

#include <span>
#include <string>
#include <vector>

#include "renderfarm/schedule/cost_map.h"

namespace mogao {

struct BalanceSimOptions {
    std::vector<int> rank_counts{4, 8, 16};                            // each in [1, LoadBalancer::kMaxRanks]
    std::vector<std::string> balancers{"pbt", "equal", "roundrobin"};  // make_load_balancer names
    int snap = 16;                                                     // pixels, for "pbt" and "equal"
    int tile = 32;                                                     // pixels, for "roundrobin"
};

// One balancer at one rank count over the whole sequence.
struct BalanceSimResult {
    std::string balancer;
    int ranks = 0;
    std::vector<double> efficiency;  // per frame, in (0, 1]
    double mean_efficiency = 0.0;
    double min_efficiency = 0.0;
    // Mean non-empty rects per rank per frame: the simulation models only how cost is spread, not the
    // per-tile overhead and lost ray coherence of many small tiles, so this column shows that price.
    double mean_rects_per_rank = 0.0;
};

// frames: actual cost map of each frame, all with the same image size and cell size, at least one.
// Returns one result per (rank count, balancer), rank counts outer, in the options' order.
// Throws std::invalid_argument on an empty or inconsistent sequence or bad options.
[[nodiscard]] std::vector<BalanceSimResult> simulate_balance(std::span<const CostMap> frames,
                                                             const BalanceSimOptions& options);

// Markdown: a table of mean/min efficiency (and rects per rank) per rank count and balancer, then a table of the ratios
// pbt/equal and pbt/roundrobin of mean efficiencies per rank count ("n/a" if a balancer is missing).
[[nodiscard]] std::string balance_table_markdown(std::span<const BalanceSimResult> results);

// Synthetic sequence for tests and for running the simulator without farm logs: a uniform
// background plus a Gaussian hot spot circling the image centre at radius 0.3*min(width, height).
struct MovingHotspot {
    ImageSize image{1920, 1080};
    int cell_size = 16;  // pixels
    int frames = 30;
    double background_seconds_per_pixel = 1e-7;
    double peak_ratio = 20.0;         // hot spot centre cost per pixel / background, >= 0
    double sigma_px = 100.0;          // Gaussian radius, pixels, > 0
    double speed_px_per_frame = 8.0;  // along the circle; small = slowly moving costs
};
[[nodiscard]] std::vector<CostMap> moving_hotspot_frames(const MovingHotspot& spec);

}  // namespace mogao
