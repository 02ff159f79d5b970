// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/frame_stats.h"

#include <algorithm>
#include <numeric>
#include <string>

#include <nlohmann/json.hpp>

#include "common/file_io.h"
#include "renderfarm/schedule/tile_cost_log.h"

namespace mogao {
namespace {

void write_json(const std::filesystem::path& file, const nlohmann::json& j) {
    const std::string text = j.dump(1) + "\n";
    write_file_atomically(file, {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
}

double mean(const std::vector<double>& v) {
    return v.empty() ? 0.0 : std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

}  // namespace

void write_stats_json(const std::filesystem::path& file, const RunInfo& run, const std::vector<FrameStats>& frames) {
    nlohmann::json j;
    j["run"] = {{"scene", run.scene},
                {"balancer", run.balancer},
                {"mpi_ranks", run.ranks},
                {"render_ranks", run.render_ranks},
                {"threads_per_rank", run.threads_per_rank},
                {"width", run.size.width},
                {"height", run.size.height},
                {"camera", run.camera},
                {"path", run.path},
                {"spp", run.spp},
                {"max_bounces", run.max_bounces},
                {"ao_samples", run.ao_samples},
                {"resolution_scale", run.resolution_scale},
                {"jpeg_quality", run.jpeg_quality},
                {"seed", run.seed},
                {"scene_load_seconds", run.scene_load_seconds},
                {"bvh_build_seconds", run.bvh_build_seconds},
                {"instanced_triangles", run.scene_load.instanced_triangles}};
    for (const MeshLoadFigures& m : run.scene_load.meshes)
        j["run"]["meshes"].push_back({{"name", m.name},
                                      {"source", m.source},
                                      {"triangles", m.triangles},
                                      {"vertices", m.vertices},
                                      {"load_seconds", m.seconds}});
    std::vector<double> frame_times, efficiencies, rays_per_second, encode, bytes;
    for (const FrameStats& f : frames) {
        j["frames"].push_back({{"frame", f.frame},
                               {"frame_seconds", f.frame_seconds},
                               {"render_phase_seconds", f.render_phase_seconds},
                               {"rank_render_seconds", f.rank_render_seconds},
                               {"rank_predicted_seconds", f.rank_predicted_seconds},
                               {"balance_efficiency", f.balance_efficiency},
                               {"rays", f.rays},
                               {"rays_per_second", f.rays_per_second},
                               {"encode_seconds", f.encode_seconds},
                               {"jpeg_bytes", f.jpeg_bytes}});
        frame_times.push_back(f.frame_seconds);
        efficiencies.push_back(f.balance_efficiency);
        rays_per_second.push_back(f.rays_per_second);
        encode.push_back(f.encode_seconds);
        bytes.push_back(static_cast<double>(f.jpeg_bytes));
    }
    j["summary"] = {
        {"frames", frames.size()},
        {"mean_frame_seconds", mean(frame_times)},
        {"max_frame_seconds", frame_times.empty() ? 0.0 : *std::max_element(frame_times.begin(), frame_times.end())},
        {"mean_balance_efficiency", mean(efficiencies)},
        {"mean_balance_efficiency_after_first",
         frames.size() > 1 ? mean(std::vector<double>(efficiencies.begin() + 1, efficiencies.end()))
                           : mean(efficiencies)},
        {"mean_rays_per_second", mean(rays_per_second)},
        {"mean_encode_seconds", mean(encode)},
        {"mean_jpeg_bytes", mean(bytes)}};
    write_json(file, j);
}

void write_tile_costs_json(const std::filesystem::path& file, ImageSize size, int cell_size,
                           const std::vector<std::vector<TileTime>>& frames) {
    const std::string text = tile_cost_log_json(TileCostLog{size, cell_size, frames});
    write_file_atomically(file, {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
}

}  // namespace mogao
