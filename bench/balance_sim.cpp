// SPDX-License-Identifier: Apache-2.0
// Load-balance simulator of the schedule stage (docs/load-balancing.md).
//
// Replays recorded per-frame tile times (tile-costs.json, written by the farm) or a synthetic moving
// hot spot, and prints markdown tables: mean/min balance efficiency of each balancer for each rank
// count, and the ratios pbt/equal and pbt/roundrobin computed in the same run. --json FILE also
// writes the figures as JSON (for bench/regenerate-docs).
#include <cstdio>
#include <exception>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "renderfarm/schedule/balance_sim.h"
#include "renderfarm/schedule/tile_cost_log.h"

int main(int argc, char** argv) {
    CLI::App app{"Simulate sort-first load balancing (pbt, equal, roundrobin) on recorded tile times"};
    std::string input;
    mogao::BalanceSimOptions options;
    int synthetic_frames = 0;
    std::string json_file;
    auto* file = app.add_option("tile_costs", input, "tile-costs.json recorded by the farm")->check(CLI::ExistingFile);
    auto* synthetic = app.add_option("--synthetic", synthetic_frames,
                                     "instead of a file, simulate this many 1920x1080 frames of a moving hot spot")
                          ->check(CLI::PositiveNumber);
    file->excludes(synthetic);
    app.add_option("--ranks", options.rank_counts, "render rank counts to simulate")
        ->delimiter(',')
        ->check(CLI::Range(1, 1 << 16))
        ->capture_default_str();
    app.add_option("--balancers", options.balancers, "balancers to compare (pbt, equal, roundrobin)")
        ->delimiter(',')
        ->capture_default_str();
    app.add_option("--snap-px", options.snap, "PBT/equal cut snap in pixels")
        ->check(CLI::PositiveNumber)
        ->capture_default_str();
    app.add_option("--tile", options.tile, "round-robin tile size in pixels")
        ->check(CLI::PositiveNumber)
        ->capture_default_str();
    app.add_option("--json", json_file, "also write the results as JSON to this file");
    CLI11_PARSE(app, argc, argv);
    if (input.empty() && synthetic_frames == 0) {
        std::fputs("give a tile-costs.json file or --synthetic FRAMES (see --help)\n", stderr);
        return 2;
    }
    try {
        std::vector<mogao::CostMap> frames;
        nlohmann::json out = {{"bench", "balance_sim"}};
        if (!input.empty()) {
            frames = mogao::tile_cost_maps(mogao::read_tile_cost_log(input));
            fmt::print("Input: {} ({} frames)\n\n", input, frames.size());
            out["input"] = {{"kind", "tile-costs"}, {"file", input}, {"frames", frames.size()}};
        } else {
            mogao::MovingHotspot spec;
            spec.frames = synthetic_frames;
            frames = mogao::moving_hotspot_frames(spec);
            fmt::print("Input: synthetic moving hot spot, {}x{}, {} frames, {} px/frame\n\n", spec.image.width,
                       spec.image.height, spec.frames, spec.speed_px_per_frame);
            out["input"] = {{"kind", "synthetic"},
                            {"width", spec.image.width},
                            {"height", spec.image.height},
                            {"frames", spec.frames},
                            {"speed_px_per_frame", spec.speed_px_per_frame}};
        }
        const auto results = mogao::simulate_balance(frames, options);
        fmt::print("{}", mogao::balance_table_markdown(results));
        if (!json_file.empty()) {
            out["snap"] = options.snap;
            out["tile"] = options.tile;
            out["results"] = nlohmann::json::array();
            for (const auto& r : results)
                out["results"].push_back({{"ranks", r.ranks},
                                          {"balancer", r.balancer},
                                          {"frames", r.efficiency.size()},
                                          {"mean_efficiency", r.mean_efficiency},
                                          {"min_efficiency", r.min_efficiency},
                                          {"mean_rects_per_rank", r.mean_rects_per_rank}});
            std::ofstream f(json_file);
            f << out.dump(1) << '\n';
            if (!f.flush()) throw std::runtime_error("cannot write " + json_file);
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "mogao_balance_sim: %s\n", e.what());
        return 1;
    }
    return 0;
}
