// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/farm.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <ctime>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "common/file_io.h"
#include "renderfarm/farm/render_threads.h"
#include "renderfarm/trace/renderer.h"

namespace mogao {
namespace {

void drop_textures(Scene& scene) {
    std::size_t dropped = 0;
    for (Mesh& mesh : scene.meshes) {
        dropped += mesh.texture ? 1 : 0;
        mesh.texture.reset();
        std::vector<Eigen::Vector2f>().swap(mesh.uvs);  // uvs only with a texture (mesh.h)
    }
    if (dropped > 0) spdlog::info("admin: {} texture(s) dropped (only render ranks shade)", dropped);
}

// Open MPI 4.1's mpirun ends an aborted job only when every remote daemon has confirmed it; the
// daemon of a host behind a cut link never does, and TCP would take minutes to give up on it. The
// admin is started by mpirun itself (its parent: the launcher's mpirun, systemd's main process),
// and MPI_Abort has that mpirun kill it, so the admin cannot wait itself: before MPI_Abort it forks
// a reaper in its own session (out of reach of the kill of the rank's process group), holding no
// descriptor (the link's listening socket must be free for the restarted farm), which ends mpirun
// if it still runs `grace_ms` later (an abort over hosts that answer takes well under that). The ranks on hosts that
// still answer lose their daemon's connection and are ended by it; systemd restarts the farm over the hosts that answer
// (systemd/mogao-farm-launch). Nothing happens when the admin's parent is not mpirun.
constexpr long kAbortGraceMs = 500;

bool process_is_mpirun(pid_t pid) {
    std::ifstream comm_file("/proc/" + std::to_string(pid) + "/comm");
    std::string comm;
    std::getline(comm_file, comm);
    return comm == "mpirun" || comm == "mpiexec" || comm == "orterun";
}

void end_mpirun_if_abort_hangs(long grace_ms) {
    const pid_t mpirun = getppid();
    if (!process_is_mpirun(mpirun)) return;
    const std::string message = fmt::format(
        "mogao-farm[0] critical: admin: mpirun (pid {}) did not end the aborted job within {} s (a host "
        "unreachable?): ending it\n",
        mpirun, double(grace_ms) / 1e3);
    const std::string comm_path = "/proc/" + std::to_string(mpirun) + "/comm";
    if (fork() != 0) return;  // the admin (or no reaper when fork failed) goes on to MPI_Abort
    // The reaper: only async-signal-safe calls from here on (the admin has threads).
    setsid();
    close_range(3, ~0U, 0);
    timespec wait{grace_ms / 1000, (grace_ms % 1000) * 1000 * 1000};
    while (nanosleep(&wait, &wait) != 0) {}
    char comm[16] = {};
    const int fd = open(comm_path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd >= 0) {
        const ssize_t n = read(fd, comm, sizeof comm - 1);
        close(fd);
        // Still that mpirun (not a reused pid): "mpirun\n" etc.
        if (n > 0 && (std::strncmp(comm, "mpirun", 6) == 0 || std::strncmp(comm, "mpiexec", 7) == 0 ||
                      std::strncmp(comm, "orterun", 7) == 0)) {
            (void)write(STDERR_FILENO, message.data(), message.size());
            timespec flush{0, 200 * 1000 * 1000};  // mpirun forwards the line before it ends
            nanosleep(&flush, nullptr);
            kill(mpirun, SIGKILL);
        }
    }
    _exit(0);
}

using Clock = std::chrono::steady_clock;

// Tells the launcher of the restart which ranks were lost (FarmSetup::lost_ranks_file). A failure is
// logged and ignored: the abort must go ahead, and the launcher then checks every host as usual.
void write_lost_ranks(const std::filesystem::path& file, const std::vector<int>& ranks) {
    if (file.empty()) return;
    std::string text;
    for (int r : ranks) text += std::to_string(r) + "\n";
    try {
        write_file_atomically(file, {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
    } catch (const std::exception& e) {
        spdlog::error("admin: cannot write the lost ranks to {}: {}", file.string(), e.what());
    }
}

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// What the admin job is told of the run (RunInfo), logged once: the scene's load and its BVH's build.
RunInfo describe_run(const MpiSession& mpi, const FarmSetup& setup, const DispatchSettings& dispatch,
                     const SceneLoadReport& report, double load_seconds, double max_bvh) {
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
    spdlog::info("{} render rank(s), {} render thread(s) each", run.render_ranks, run.threads_per_rank);
    for (const MeshLoadFigures& m : report.meshes)
        spdlog::info("  mesh {:<12} {:>9} triangles {:>8} vertices {:6.3f} s  {}", m.name, m.triangles, m.vertices,
                     m.seconds, m.source);
    return run;
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
    if (!mpi.all(scene.has_value())) {
        if (!scene) spdlog::error("rank {}: {}", mpi.rank(), error);
        return 1;
    }
    // An admin with render ranks never shades a pixel: the textures and their mip chains would only
    // sit in its memory for months.
    if (mpi.is_admin() && mpi.size() > 1) drop_textures(*scene);

    // 2. Render ranks (or a lone admin) build the BVH; the admin of a larger farm only schedules.
    std::optional<Renderer> renderer;
    // The denoiser's guides at pixel centres, traced on the renderer's BVH for frames whose samples
    // are jittered: the renderer's own jittered first hits cost less CPU but served frames worse
    // (serve bench). A frame sampled at pixel centres takes its own first hits instead (a moving
    // frame from the radiance cache: RendererOptions::jitter_cached_one_spp).
    std::optional<GuidePass> guides;
    double bvh_seconds = 0.0;
    const bool renders = !mpi.is_admin() || mpi.size() == 1;
    DispatchSettings dispatch = setup.dispatch;
    dispatch.threads = agree_render_threads(mpi, setup.dispatch.threads, renders);
    if (renders) {
        const auto bvh_start = Clock::now();
        try {
            RendererOptions options;
            options.embree_config = fmt::format("threads={}", dispatch.threads);
            options.jitter_cached_one_spp = setup.jitter_cached_one_spp;
            renderer.emplace(*scene, options);
            guides.emplace(*scene, renderer->render_scene());
        } catch (const std::exception& e) {
            error = e.what();
            spdlog::error("rank {}: cannot build the BVH: {}", mpi.rank(), error);
        }
        bvh_seconds = seconds_since(bvh_start);
    }
    double max_bvh = 0.0;
    MPI_Reduce(&bvh_seconds, &max_bvh, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
    if (!mpi.all(!renders || renderer.has_value())) return 1;

    dispatch.exposure = scene->exposure;
    dispatch.tone_map = scene->tone_map;
    if (!mpi.is_admin()) {
        serve_render_rank(renderer ? &*renderer : nullptr, dispatch, error, guides ? &*guides : nullptr);
        return 0;
    }

    RunInfo run = describe_run(mpi, setup, dispatch, report, load_seconds, max_bvh);

    // 3. The admin job. One boundary catches what it throws; the dispatcher's destructor releases
    //    the render ranks on every path out.
    FrameDispatcher dispatcher(mpi, dispatch, renderer ? &*renderer : nullptr, guides ? &*guides : nullptr);
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
        write_lost_ranks(setup.lost_ranks_file, dispatcher.lost_ranks());
        end_mpirun_if_abort_hangs(kAbortGraceMs);
        MPI_Abort(MPI_COMM_WORLD, kRankLostExitCode);
    }
    return status;
}

}  // namespace mogao
