// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/path_tour.h"

#include <algorithm>
#include <chrono>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "common/camera_path.h"
#include "common/file_io.h"
#include "common/jpeg_codec.h"
#include "common/png_io.h"
#include "renderfarm/encode/contact_sheet.h"

namespace mogao {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

}  // namespace

int run_path_tour(const PathTour& tour, FrameDispatcher& farm, const Scene& scene, RunInfo& run) {
    const std::vector<ViewerPose> poses = make_camera_path(tour.path, scene.viewer, tour.frames);
    const ImageSize size = render_size(tour.view_template);
    run.size = size;
    run.camera = std::holds_alternative<CylinderScreen>(tour.view_template.camera) ? "cylinder" : "pinhole";
    run.path = tour.path;
    run.spp = tour.view_template.quality.spp;
    run.max_bounces = tour.view_template.quality.max_bounces;
    run.ao_samples = tour.view_template.quality.ao_samples;
    run.jpeg_quality = tour.view_template.quality.jpeg_quality;
    run.resolution_scale = tour.view_template.quality.resolution_scale;
    run.seed = tour.view_template.seed;

    std::filesystem::create_directories(tour.out_dir);
    const int sheet_every =
        tour.contact_sheet_frames > 0 ? std::max(1, static_cast<int>(poses.size()) / tour.contact_sheet_frames) : 0;
    JpegEncoder encoder;
    std::vector<FrameStats> stats;
    std::vector<std::vector<TileTime>> tile_log;
    std::vector<Rgb8Image> thumbnails;
    for (std::size_t f = 0; f < poses.size(); ++f) {
        const auto frame_start = Clock::now();
        ViewRequest view = tour.view_template;
        view.frame_id = tour.first_frame_id + f;
        view.pose = poses[f];
        view.request_time_ns =
            std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
                .count();
        DispatchedFrame frame = farm.render(view);

        const auto encode_start = Clock::now();
        const std::vector<std::uint8_t> jpeg = encoder.encode(frame.image, view.quality.jpeg_quality);
        frame.stats.encode_seconds = seconds_since(encode_start);
        frame.stats.jpeg_bytes = jpeg.size();
        write_file_atomically(tour.out_dir / fmt::format("frame-{:04d}.jpg", f), jpeg);
        if (tour.save_raw) write_ppm(tour.out_dir / fmt::format("frame-{:04d}.ppm", f), frame.image);
        if (sheet_every > 0 && f % static_cast<std::size_t>(sheet_every) == 0 &&
            static_cast<int>(thumbnails.size()) < tour.contact_sheet_frames)
            thumbnails.push_back(downscale_box(frame.image, {480, std::max(1, 480 * size.height / size.width)}));
        frame.stats.frame_seconds = seconds_since(frame_start);
        spdlog::info("frame {:4d}: {:6.3f} s, efficiency {:.3f}, {:6.2f} Mrays/s, encode {:5.1f} ms, {:7d} bytes", f,
                     frame.stats.frame_seconds, frame.stats.balance_efficiency, frame.stats.rays_per_second / 1e6,
                     frame.stats.encode_seconds * 1e3, frame.stats.jpeg_bytes);
        stats.push_back(std::move(frame.stats));
        tile_log.push_back(std::move(frame.tiles));
    }
    farm.stop();
    write_stats_json(tour.out_dir / "stats.json", run, stats);
    write_tile_costs_json(tour.out_dir / "tile-costs.json", size, farm.cell_size(), tile_log);
    if (!thumbnails.empty()) write_png(tour.out_dir / "contact-sheet.png", make_contact_sheet(thumbnails, 4, 480));
    return 0;
}

}  // namespace mogao
