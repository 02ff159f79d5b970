// SPDX-License-Identifier: Apache-2.0
// The headless tour: the admin renders a scripted camera path (camera_path.h) on the farm and
// writes DIR/frame-NNNN.jpg (TurboJPEG, full frame encoded once on the admin), optional lossless
// frame-NNNN.ppm, stats.json (per-frame figures), tile-costs.json (measured tile times, input of
// bench/balance_sim) and contact-sheet.png.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "common/view_request.h"
#include "renderfarm/farm/frame_dispatcher.h"
#include "renderfarm/farm/frame_stats.h"
#include "renderfarm/scene/scene.h"

namespace mogao {

struct PathTour {
    std::string path = "walk";  // walk | orbit | path file
    int frames = 60;
    ViewRequest view_template;  // camera, size, quality, seed; the pose comes from the path
    std::filesystem::path out_dir;
    bool save_raw = false;          // also write lossless frame-NNNN.ppm
    int contact_sheet_frames = 12;  // 0: no contact sheet
    // ViewRequest::frame_id of the first frame (then +1 per frame). Sampling depends on (seed,
    // frame_id) (renderer.h): a live frame is reproduced with frame_id = its request id.
    std::uint64_t first_frame_id = 0;
};

// Returns the exit code; throws PathError / FarmError / file errors, which run_farm reports.
int run_path_tour(const PathTour& tour, FrameDispatcher& farm, const Scene& scene, RunInfo& run);

}  // namespace mogao
