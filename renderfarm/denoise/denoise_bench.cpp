// SPDX-License-Identifier: Apache-2.0
// Error at equal time, with and without the denoiser, on the real grotto (docs/renderer.md, "Denoiser").
//
//   mogao_bench_denoise [--scene scenes/grotto.json] [--scans DIR] [--width 480] [--height 270]
//                       [--reps 2] [--ref-spp 128] [--threads 1] [--iterations 5] [--sigma-colour 4]
//                       [--sigma-normal 0.5] [--sigma-depth 1]   (AtrousParams, atrous_filter.h)
//
// One view (the grotto walk's frame 30 on the bench cylinder screen, default quality knobs but spp).
// Raw frames at 1, 2, 4, ... 32 spp and denoised frames at 1, 2, 4 spp (render + guide pass + filter)
// are compared by PSNR of their sRGB8 frames (frame_error.h) against one render at --ref-spp.
// Equal time: the raw PSNR at the denoised frame's time is interpolated linearly in log(time)
// between the two raw frames that bracket it; the time raw rendering needs to reach the denoised
// PSNR likewise. Then what the guides cost: a 1-spp frame with the renderer's own first hits as
// guides against the render plus the guide pass, path traced and from a warm radiance cache.
// Times are the calling thread's CPU time (render and guides on one thread, the
// filter on --threads), best of --reps, all measured in this run. Exits 77 without the scans.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "common/camera_path.h"
#include "common/thread_clock.h"
#include "renderfarm/denoise/atrous_filter.h"
#include "renderfarm/denoise/frame_error.h"
#include "renderfarm/denoise/guide_pass.h"
#include "renderfarm/scene/scene_file.h"
#include "renderfarm/trace/render_timing.h"
#include "renderfarm/trace/renderer.h"

namespace {

using namespace mogao;

struct Timed {
    RgbFloatImage image;
    double seconds = 1e300;
};

Timed render(Renderer& renderer, ViewRequest view, int spp, int reps) {
    view.quality.spp = spp;
    TimedFrame f = render_fastest_of(renderer, view, reps);
    return {std::move(f.image), f.seconds};
}

struct Point {
    int spp = 0;
    double seconds = 0.0;
    double db = 0.0;
};

// Linear interpolation of y over log(x) through the points (x ascending); NaN outside their range.
double interpolate_log(const std::vector<Point>& raw, double x, bool by_time) {
    for (std::size_t i = 0; i + 1 < raw.size(); ++i) {
        const double x0 = by_time ? raw[i].seconds : raw[i].db, x1 = by_time ? raw[i + 1].seconds : raw[i + 1].db;
        if (x < x0 || x > x1) continue;
        const double y0 = by_time ? raw[i].db : std::log(raw[i].seconds);
        const double y1 = by_time ? raw[i + 1].db : std::log(raw[i + 1].seconds);
        const double f = by_time ? (std::log(x) - std::log(x0)) / (std::log(x1) - std::log(x0)) : (x - x0) / (x1 - x0);
        const double y = y0 + f * (y1 - y0);
        return by_time ? y : std::exp(y);
    }
    return std::nan("");
}

struct Options {
    std::filesystem::path scene_file = std::filesystem::path(MOGAO_SOURCE_DIR) / "scenes" / "grotto.json";
    SceneLoadOptions load;
    int width = 480, height = 270, reps = 2, ref_spp = 128;
    AtrousParams params;  // --threads, --iterations, --sigma-colour, --sigma-normal, --sigma-depth
};

bool scene_uses_scans(const std::filesystem::path& scene_file) {
    std::ifstream in(scene_file);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    return text.find("{scans}") != std::string::npos;
}

// Guide pass + filter for one raw frame; returns the denoised image and the added CPU seconds.
Timed denoise(GuidePass& pass, const ViewRequest& view, const RgbFloatImage& raw, const AtrousParams& params, int reps,
              double* filter_seconds) {
    Timed best;
    AtrousDenoiser denoiser;
    for (int r = 0; r < reps; ++r) {
        const double t0 = thread_cpu_seconds();
        Result<GuideBuffers> guides = pass.render_frame(view);
        const double t1 = thread_cpu_seconds(), w1 = monotonic_seconds();
        RgbFloatImage out;
        if (!guides.ok()) throw std::runtime_error(guides.error().message);
        if (Status s = denoiser.run(raw, *guides, params, out); !s.ok()) throw std::runtime_error(s.error().message);
        // The filter may run on several threads: charge its wall time (it is the frame's latency).
        const double filter = params.threads == 1 ? thread_cpu_seconds() - t1 : monotonic_seconds() - w1;
        if (t1 - t0 + filter < best.seconds) {
            best = {std::move(out), t1 - t0 + filter};
            *filter_seconds = filter;
        }
    }
    return best;
}

// What the denoiser's guides cost: one 1-spp frame rendered with its own first camera hits as
// guides (Renderer::render with guides, what the farm does), against the same render followed by
// the guide pass (a second primary ray per pixel centre), CPU seconds, best of `reps` each; with
// `cached` the frame reads a radiance cache warmed by a few frames first (the farm's moving frames).
void print_guide_cost(Renderer& renderer, GuidePass& pass, ViewRequest view, int reps, bool cached) {
    view.quality.spp = 1;
    view.radiance_cache = cached;
    renderer.clear_radiance_cache();
    double own = 1e300, separate = 1e300;
    for (int r = 0; r < reps + (cached ? 4 : 0); ++r) {
        view.frame_id = 1000 + static_cast<std::uint64_t>(r);
        renderer.begin_frame(view);
        RgbFloatImage frame(renderer.render_size());
        GuideBuffers guides(frame.size);
        double t0 = thread_cpu_seconds();
        (void)renderer.render(PixelRect::whole(frame.size), frame, 0, 0, guides);
        const double with_own = thread_cpu_seconds() - t0;
        t0 = thread_cpu_seconds();
        (void)renderer.render(PixelRect::whole(frame.size), frame);
        if (Result<GuideBuffers> g = pass.render_frame(view); !g.ok()) throw std::runtime_error(g.error().message);
        if (cached && r < 4) continue;  // warming the cache
        own = std::min(own, with_own);
        separate = std::min(separate, thread_cpu_seconds() - t0);
    }
    std::printf("| %s | %.1f | %.1f | %.3f |\n", cached ? "radiance cache (moving frame)" : "path traced", 1e3 * own,
                1e3 * separate, own / separate);
}

int run(const Options& o) {
    SceneLoadReport report;
    const Scene scene = load_scene(o.scene_file, o.load, &report);
    ViewRequest view;
    view.size = {o.width, o.height};
    view.camera = CylinderScreen{3.0, 150.0, 0.2, 2.8, {0.0, 1.6, 0.0}};
    view.pose = make_camera_path("walk", scene.viewer, 60)[30];
    Renderer renderer(scene, RendererOptions{"threads=1"});
    GuidePass pass(scene, "threads=1");
    std::printf(
        "# denoiser at equal time: %s, %dx%d cylinder frame, render on one thread, filter on %d, best of %d\n\n",
        o.scene_file.filename().c_str(), o.width, o.height, o.params.threads, o.reps);
    ViewRequest reference_view = view;
    reference_view.seed = view.seed + 1;  // independent samples: no raw frame is a prefix of the reference
    const Timed reference = render(renderer, reference_view, o.ref_spp, 1);
    std::printf("Reference: %d spp (%.1f s).\n\n| frame | spp | CPU ms | PSNR dB |\n|---|--:|--:|--:|\n", o.ref_spp,
                reference.seconds);
    const auto db = [&](const RgbFloatImage& im) {
        return display_psnr(im, reference.image, scene.exposure, scene.tone_map);
    };
    std::vector<Point> raw;
    std::vector<Timed> raw_frames;
    for (int spp = 1; spp <= 32 && spp < o.ref_spp; spp *= 2) {
        raw_frames.push_back(render(renderer, view, spp, o.reps));
        raw.push_back({spp, raw_frames.back().seconds, db(raw_frames.back().image)});
        std::printf("| raw | %d | %.1f | %.2f |\n", spp, 1e3 * raw.back().seconds, raw.back().db);
    }
    const AtrousParams& params = o.params;
    std::vector<Point> denoised;
    double filter_s = 0.0;
    for (std::size_t k = 0; k < 3 && k < raw.size(); ++k) {
        const Timed d = denoise(pass, view, raw_frames[k].image, params, o.reps, &filter_s);
        denoised.push_back({raw[k].spp, raw[k].seconds + d.seconds, db(d.image)});
        std::printf("| denoised (render + guides + filter %.1f ms) | %d | %.1f | %.2f |\n", 1e3 * filter_s, raw[k].spp,
                    1e3 * denoised.back().seconds, denoised.back().db);
    }
    std::printf(
        "\n| denoised spp | raw PSNR at equal time dB | gain dB | raw time for the same PSNR / denoised time |\n"
        "|--:|--:|--:|--:|\n");
    for (const Point& d : denoised) {
        const double equal_time_db = interpolate_log(raw, d.seconds, true);
        const double raw_time = interpolate_log(raw, d.db, false);
        std::printf("| %d | %.2f | %+.2f | %s |\n", d.spp, equal_time_db, d.db - equal_time_db,
                    std::isnan(raw_time) ? "beyond the raw range" : std::to_string(raw_time / d.seconds).c_str());
    }
    std::printf(
        "\n| 1-spp frame | render with its own guides ms | render + guide pass ms | ratio |\n|---|--:|--:|--:|\n");
    print_guide_cost(renderer, pass, view, o.reps, false);
    print_guide_cost(renderer, pass, view, o.reps, true);
    std::printf("\nratio filter / raw 1 spp render = %.3f; filter %.1f ms per %dx%d frame (%.1f ns per pixel)\n",
                filter_s / raw[0].seconds, 1e3 * filter_s, o.width, o.height,
                1e9 * filter_s / (double(o.width) * o.height));
    // The filter's two builds (common/cpu_level.h) on the 1-spp frame, alternated, best of reps each.
    AtrousParams baseline = params;
    baseline.cpu = CpuLevel::baseline;
    double automatic_s = 1e300, baseline_s = 1e300, f = 0.0;
    for (int r = 0; r < std::max(o.reps, 3); ++r) {
        (void)denoise(pass, view, raw_frames[0].image, params, 1, &f);
        automatic_s = std::min(automatic_s, f);
        (void)denoise(pass, view, raw_frames[0].image, baseline, 1, &f);
        baseline_s = std::min(baseline_s, f);
    }
    std::printf("filter, this CPU's build (%s) / the x86-64 baseline build = %.3f (%.1f ms / %.1f ms)\n",
                use_x86_64_v3(CpuLevel::automatic) ? "x86-64-v3" : "baseline", automatic_s / baseline_s,
                1e3 * automatic_s, 1e3 * baseline_s);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    Options o;
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string flag = argv[i];
        const std::string value = argv[i + 1];
        if (flag == "--scene") o.scene_file = value;
        else if (flag == "--scans") o.load.scans_dir = value;
        else if (flag == "--width") o.width = std::stoi(value);
        else if (flag == "--height") o.height = std::stoi(value);
        else if (flag == "--reps") o.reps = std::stoi(value);
        else if (flag == "--ref-spp") o.ref_spp = std::stoi(value);
        else if (flag == "--threads") o.params.threads = std::stoi(value);
        else if (flag == "--iterations") o.params.iterations = std::stoi(value);
        else if (flag == "--sigma-colour") o.params.sigma_colour = std::stof(value);
        else if (flag == "--sigma-normal") o.params.sigma_normal = std::stof(value);
        else if (flag == "--sigma-depth") o.params.sigma_depth = std::stof(value);
        else {
            std::fprintf(stderr, "unknown flag %s\n", flag.c_str());
            return 2;
        }
    }
    if (scene_uses_scans(o.scene_file) && !std::filesystem::exists(resolve_scans_dir(o.scene_file, o.load))) {
        std::printf("SKIP: real scans not found at %s\n", resolve_scans_dir(o.scene_file, o.load).c_str());
        return 77;
    }
    try {
        return run(o);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "mogao_bench_denoise: %s\n", e.what());
        return 1;
    }
}
