// The farm's frame loop under Open MPI (sort-first): rank 0, the admin, assigns each render rank
// its rects with the load balancer (PBT by default), the ranks trace and send back sRGB8 pixels and
// per-tile times, the admin composites the frame, encodes it once with TurboJPEG and re-balances
// from the measured times. Every rank loads the scene itself; only frames leave the farm.
//
// Errors: a rank that cannot load the scene or render a frame reports it (stderr, naming the rank
// and reason) and the whole job stops cleanly with exit code 1 — never a hang: scene loading ends in
// a collective status check, and render failures travel back to the admin in the frame reply.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "renderfarm/farm/frame_stats.h"
#include "renderfarm/farm/mpi_session.h"
#include "renderfarm/scene/scene_file.h"
#include "renderfarm/view/view_request.h"

namespace mogao {

struct FarmJob {
    std::filesystem::path scene_file;
    SceneLoadOptions scene_options;
    std::string path = "walk";        // walk | orbit | path file
    int frames = 60;
    ViewRequest view_template;        // camera, size, quality, seed; the pose comes from the path
    std::string balancer = "pbt";     // pbt | equal | roundrobin
    int snap = 16;                    // PBT/equal split positions snap to multiples of this (pixels)
    int roundrobin_tile = 32;         // tile size of the round-robin mode (pixels)
    int cell_size = 16;               // tile timing / cost-map cell (pixels)
    int threads = 1;                  // render threads per rank
    std::filesystem::path out_dir;
    bool save_raw = false;            // also write lossless frame-NNNN.ppm
    int contact_sheet_frames = 12;    // 0: no contact sheet
};

// Runs the job on every rank of the session; returns the process exit code (0 = success).
int run_farm_job(const MpiSession& mpi, const FarmJob& job);

}  // namespace mogao
