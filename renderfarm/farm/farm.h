// SPDX-License-Identifier: Apache-2.0
// Setting up a farm under Open MPI (sort-first): every rank loads the scene itself, the render ranks
// build the Embree BVH, then rank 0 (the admin) runs an admin job — a scripted camera path
// (path_tour.h) — on a FrameDispatcher while ranks 1..N-1 serve frames. Only frames leave the farm.
//
// Errors: a rank that cannot load the scene or build its BVH reports it (stderr, naming the rank and
// reason) and the whole job stops cleanly with exit code 1 — never a hang: setup ends in collective
// status checks, frame failures travel back to the admin in the frame reply (FarmError), and a rank
// that does not reply within the frame deadline aborts the job (kRankLostExitCode).
#pragma once

#include <filesystem>
#include <functional>
#include <string>

#include "renderfarm/farm/frame_dispatcher.h"
#include "renderfarm/farm/frame_stats.h"
#include "renderfarm/farm/mpi_session.h"
#include "renderfarm/scene/scene_file.h"

namespace mogao {

struct FarmSetup {
    std::filesystem::path scene_file;
    SceneLoadOptions scene_options;
    DispatchSettings dispatch;  // exposure is taken from the scene
    // RendererOptions::jitter_cached_one_spp of the render ranks (off: a moving frame from the
    // radiance cache samples pixel centres and takes its guides from its own camera rays).
    bool jitter_cached_one_spp = false;
    // Where the admin writes the ranks it names lost (one decimal rank per line, written atomically)
    // before it aborts the job with kRankLostExitCode; empty = nowhere. systemd/mogao-farm-launch
    // reads it at the restart to leave those ranks' hosts out without waiting for their health check.
    std::filesystem::path lost_ranks_file;
};

// What the admin does once the farm stands: returns the process exit code.
using AdminJob = std::function<int(FrameDispatcher&, const Scene&, RunInfo&)>;

// The exit code of a job aborted because a render rank stopped answering (RankTimeout).
inline constexpr int kRankLostExitCode = 3;

// Runs on every rank; returns the process exit code (0 = success, 1 = the job failed). A lost
// render rank (frame_dispatcher.h, RankTimeout) ends the whole MPI job with MPI_Abort and
// kRankLostExitCode, so mpirun exits and systemd restarts the service.
int run_farm(const MpiSession& mpi, const FarmSetup& setup, const AdminJob& admin_job);

}  // namespace mogao
