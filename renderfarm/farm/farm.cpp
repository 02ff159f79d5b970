// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/farm.h"

#include <algorithm>
#include <chrono>
#include <optional>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "renderfarm/trace/renderer.h"

namespace mogao {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// True on every rank when `ok` is true on every rank (a collective: all ranks must call it).
bool all_ranks(bool ok) {
    int mine = ok ? 1 : 0, all = 0;
    MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    return all == 1;
}

}  // namespace

int run_farm(const MpiSession& mpi, const FarmSetup& setup, const AdminJob& admin_job) {
    // 1. Every rank loads the scene itself; a failure on any rank stops all of them.
    const auto load_start = Clock::now();
    std::optional<Scene> scene;
    SceneLoadReport report;
    std::string error;
    try {
        scene = load_scene(setup.scene_file, setup.scene_options, &report);
    } catch (const std::exception& e) {
        error = e.what();
    }
    const double load_seconds = seconds_since(load_start);
    if (!all_ranks(scene.has_value())) {
        if (!scene) spdlog::error("rank {}: {}", mpi.rank(), error);
        return 1;
    }

    // 2. Render ranks (or a lone admin) build the BVH; the admin of a larger farm only schedules.
    std::optional<Renderer> renderer;
    double bvh_seconds = 0.0;
    const bool renders = !mpi.is_admin() || mpi.size() == 1;
    if (renders) {
        const auto bvh_start = Clock::now();
        try {
            RendererOptions options;
            options.embree_config = fmt::format("threads={}", setup.dispatch.threads);
            renderer.emplace(*scene, options);
        } catch (const std::exception& e) {
            error = e.what();
            spdlog::error("rank {}: cannot build the BVH: {}", mpi.rank(), error);
        }
        bvh_seconds = seconds_since(bvh_start);
    }
    double max_bvh = 0.0;
    MPI_Reduce(&bvh_seconds, &max_bvh, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
    if (!all_ranks(!renders || renderer.has_value())) return 1;

    DispatchSettings dispatch = setup.dispatch;
    dispatch.exposure = scene->exposure;
    dispatch.tone_map = scene->tone_map;
    if (!mpi.is_admin()) {
        serve_render_rank(renderer ? &*renderer : nullptr, dispatch, error);
        return 0;
    }

    RunInfo run;
    run.scene = setup.scene_file.string();
    run.balancer = dispatch.balancer;
    run.ranks = mpi.size();
    run.render_ranks = std::max(1, mpi.render_ranks());
    run.threads_per_rank = dispatch.threads;
    run.scene_load = report;
    run.scene_load_seconds = load_seconds;
    run.bvh_build_seconds = max_bvh;
    spdlog::info("scene {}: {} triangles instanced from {} meshes, loaded in {:.2f} s; BVH {:.2f} s", run.scene,
                 report.instanced_triangles, report.meshes.size(), load_seconds, max_bvh);
    for (const MeshLoadFigures& m : report.meshes)
        spdlog::info("  mesh {:<12} {:>9} triangles {:>8} vertices {:6.3f} s  {}", m.name, m.triangles, m.vertices,
                     m.seconds, m.source);

    // 3. The admin job. One boundary catches what it throws; the dispatcher's destructor releases
    //    the render ranks on every path out.
    FrameDispatcher dispatcher(mpi, dispatch, renderer ? &*renderer : nullptr);
    int status = 1;
    try {
        status = admin_job(dispatcher, *scene, run);
    } catch (const std::exception& e) {
        spdlog::error("admin: {}", e.what());
    }
    if (dispatcher.broken()) {
        // A rank stopped answering mid-frame: the others wait in a collective that never ends, and
        // MPI_Finalize would wait for them. End the whole job so that systemd restarts the farm.
        spdlog::critical("admin: a render rank was lost; aborting the MPI job (exit code {})", kRankLostExitCode);
        MPI_Abort(MPI_COMM_WORLD, kRankLostExitCode);
    }
    return status;
}

}  // namespace mogao
