// mogao-farm: the render farm's command line. This file is the one place where the farm's stages
// are wired: scene (load) -> schedule (PBT) -> trace (Embree) -> encode (TurboJPEG), under MPI.
//
//   mpirun -n 3 mogao-farm render --scene scenes/grotto.json --frames 60 --out out/tour
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "renderfarm/farm/farm.h"
#include "renderfarm/farm/path_tour.h"
#include "renderfarm/farm/mpi_session.h"

namespace {

struct CameraFlags {
    std::string kind = "cylinder";
    double fov_deg = 60.0;
    double radius = 3.0, arc = 150.0, bottom = 0.2, top = 2.8, eye_height = 1.6;
};

void add_render_flags(CLI::App& render, mogao::FarmSetup& setup, mogao::PathTour& job, CameraFlags& camera,
                      std::string& scans) {
    auto& q = job.view_template.quality;
    render.add_option("--scene", setup.scene_file, "Scene file (JSON, docs/scene-format.md)")->required()->check(CLI::ExistingFile);
    render.add_option("--frames", job.frames, "Number of frames of the camera path")->check(CLI::Range(1, 1000000));
    render.add_option("--path", job.path, "walk | orbit | a JSON path file");
    render.add_option("--out", job.out_dir, "Output folder for frame-NNNN.jpg, stats.json, tile-costs.json, contact-sheet.png")->required();
    render.add_option("--width", job.view_template.size.width, "Frame width in pixels")->check(CLI::Range(16, 16384));
    render.add_option("--height", job.view_template.size.height, "Frame height in pixels")->check(CLI::Range(16, 16384));
    render.add_option("--camera", camera.kind, "cylinder (the projection screen's content) | pinhole")
        ->check(CLI::IsMember({"cylinder", "pinhole"}));
    render.add_option("--fov", camera.fov_deg, "Pinhole vertical field of view, degrees")->check(CLI::Range(1.0, 179.0));
    render.add_option("--screen-radius", camera.radius, "Cylinder screen radius, metres")->check(CLI::Range(0.1, 1000.0));
    render.add_option("--screen-arc", camera.arc, "Cylinder screen arc, degrees")->check(CLI::Range(1.0, 360.0));
    render.add_option("--screen-bottom", camera.bottom, "Cylinder screen bottom edge, metres above the floor");
    render.add_option("--screen-top", camera.top, "Cylinder screen top edge, metres above the floor");
    render.add_option("--spp", q.spp, "Samples per pixel")->check(CLI::Range(1, 4096));
    render.add_option("--bounces", q.max_bounces, "Path-tracing bounces (0 = direct light only)")->check(CLI::Range(0, 64));
    render.add_option("--ao", q.ao_samples, "Ambient-occlusion rays for the environment light (0 = unoccluded)")->check(CLI::Range(0, 1024));
    render.add_option("--area-samples", q.area_light_samples, "Shadow rays per area light per sample")->check(CLI::Range(1, 1024));
    render.add_option("--scale", q.resolution_scale, "Resolution scale (0, 1]")->check(CLI::Range(0.01, 1.0));
    render.add_option("--jpeg-quality", q.jpeg_quality, "TurboJPEG quality 1..100")->check(CLI::Range(1, 100));
    render.add_option("--seed", job.view_template.seed, "Sampling seed (same seed, same pixels)");
    render.add_option("--balance", setup.dispatch.balancer, "pbt | equal | roundrobin")->check(CLI::IsMember({"pbt", "equal", "roundrobin"}));
    render.add_option("--snap", setup.dispatch.snap, "PBT/equal split snap in pixels")->check(CLI::IsMember({4, 8, 16, 32}));
    render.add_option("--rr-tile", setup.dispatch.roundrobin_tile, "Round-robin tile size in pixels")->check(CLI::Range(8, 1024));
    render.add_option("--threads", setup.dispatch.threads, "Render threads per rank")->check(CLI::Range(1, 256));
    render.add_option("--scans", scans, "Folder of the real scans (default: $MOGAO_SCANS_DIR or ../shared/data/scans)");
    render.add_flag("--save-raw", job.save_raw, "Also write lossless frame-NNNN.ppm");
    render.add_option("--contact-sheet", job.contact_sheet_frames, "Frames on the contact sheet (0 = none)")->check(CLI::Range(0, 64));
}

}  // namespace

int main(int argc, char** argv) {
    mogao::MpiSession mpi(&argc, &argv);
    auto logger = spdlog::stderr_color_mt("mogao-farm");
    spdlog::set_default_logger(logger);
    // journald-friendly: no timestamps of our own (the journal adds them), rank and level first.
    spdlog::set_pattern(fmt::format("mogao-farm[{}] %l: %v", mpi.rank()));
    if (!mpi.is_admin()) spdlog::set_level(spdlog::level::warn);

    CLI::App app{"mogao-farm: the mogao render farm (Embree ray tracing, sort-first PBT over MPI ranks, JPEG frames)"};
    app.require_subcommand(1);
    mogao::FarmSetup setup;
    mogao::PathTour job;
    CameraFlags camera;
    std::string scans;
    CLI::App* render = app.add_subcommand("render", "Render a camera path headless into numbered JPEG frames");
    add_render_flags(*render, setup, job, camera, scans);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return mpi.is_admin() ? app.exit(e) : (e.get_exit_code() == 0 ? 0 : 2);
    }
    if (camera.kind == "pinhole") {
        job.view_template.camera = mogao::PinholeCamera{camera.fov_deg};
    } else {
        if (!(camera.top > camera.bottom)) {
            if (mpi.is_admin()) spdlog::error("--screen-top ({}) must be above --screen-bottom ({})", camera.top, camera.bottom);
            return 2;
        }
        job.view_template.camera =
            mogao::CylinderScreen{camera.radius, camera.arc, camera.bottom, camera.top, {0.0, camera.eye_height, 0.0}};
    }
    setup.scene_options.scans_dir = scans;
    return mogao::run_farm(mpi, setup, [&](mogao::FrameDispatcher& farm, const mogao::Scene& scene, mogao::RunInfo& run) {
        return mogao::run_path_tour(job, farm, scene, run);
    });
}
