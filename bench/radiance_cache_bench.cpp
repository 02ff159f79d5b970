// SPDX-License-Identifier: Apache-2.0
// The radiance cache (renderfarm/trace/radiance_cache.h, cached_packet.h) as time against error:
// cached frames of a moving view against the path tracer at 1, 2 and 4 spp measured in the same
// run (ratios are meaningful on any machine, absolute times are not).
//
//   mogao_bench_radiance_cache [--scene scenes/grotto.json] [--scans DIR] [--width 480] [--height 270]
//                              [--bounces 1] [--ref-spp 256] [--warm-frames 10] [--reps 2]
//                              [--write-docs docs/renderer.md] [--png-dir DIR]
//
// View: the grotto's cylinder screen at pose 30 of the scene's 60-pose `walk` path (as
// mogao_bench_sampling), --bounces bounces, one thread. A cached setting first draws --warm-frames
// frames along the path just before pose 30 (the visitor walking up to it: what the cache holds
// when pose 30 is reached; 0 = a cold cache) on a fresh Renderer, then pose 30, timed. Error against
// a converged path-traced reference of pose 30 (--ref-spp, another seed, every core): relMSE of
// linear radiance (bench/quality/image_metrics.h) and GMSD of the tone-mapped sRGB8 frames
// (bench/quality/gmsd.h: counts blur and blocks). "mean of 16" rows average 16 frames at pose 30
// (the frame-to-frame noise averaged out), their sub-pixel positions jittered as the path tracer's:
// what is left is the cache's bias; one more row averages the pixel centres that served moving
// frames sample (RendererOptions::jitter_cached_one_spp off), whose mean keeps their aliasing. Times: the render
// thread's CPU time for pose 30, best of --reps (each rep on a fresh cache). --write-docs FILE
// replaces the `<!-- generated:radiance-cache -->` block of FILE; --png-dir DIR writes the reference
// and each setting's frame at pose 30 to look at.
#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bench/quality/bench_report.h"
#include "bench/quality/gmsd.h"
#include "bench/quality/image_metrics.h"
#include "bench/trace_reference.h"
#include "common/camera_path.h"
#include "common/png_io.h"
#include "common/thread_clock.h"
#include "renderfarm/scene/scene_file.h"
#include "renderfarm/trace/film.h"
#include "renderfarm/trace/renderer.h"

namespace {

using namespace mogao;
using bench::arg_int;
using bench::arg_str;
using bench::fmt;
using bench::reference_frame;

struct Setting {
    std::string label;
    std::string png;
    bool cached = false;
    int spp = 1;
    int warm = 0;
    float cell_footprints = 4.0f;
    int train_one_in = 16;
    int frames_averaged = 1;
    int visibility_min_samples = 8;  // RadianceCacheOptions: 0 traces every shadow ray
    int visibility_recheck_one_in = 8;
    // RendererOptions::jitter_cached_one_spp: served moving frames sample pixel centres (off); the
    // mean-of-16 rows that measure the cache's bias jitter, as the path tracer does, so that the
    // mean integrates each pixel's area and what is left is the cache's bias, not aliasing.
    bool jitter_cached = false;
    bool cache_direct = true;  // RadianceCacheOptions: cells whose lights are all known keep their direct light
};

struct Row {
    double seconds = std::numeric_limits<double>::infinity();
    double rays_per_pixel = 0.0;
    double relmse = 0.0;
    double gmsd = 0.0;
};

struct Bench {
    const Scene& scene;
    std::vector<ViewerPose> path;
    ViewRequest view;  // pose 30
    RgbFloatImage reference;
    Rgb8Image reference8;

    [[nodiscard]] Rgb8Image display(const RgbFloatImage& f) const {
        Rgb8Image out(f.size);
        to_srgb8(f, PixelRect::whole(f.size), scene.exposure, out, scene.tone_map);
        return out;
    }

    [[nodiscard]] ViewRequest at(std::size_t pose, std::uint64_t frame_id, const Setting& s) const {
        ViewRequest v = view;
        v.pose = path[pose];
        v.frame_id = frame_id;
        v.quality.spp = s.spp;
        v.radiance_cache = s.cached;
        return v;
    }

    // Pose 30 after the setting's warm-up, on `renderer` (a fresh cache); `seconds` its CPU time.
    RgbFloatImage draw(Renderer& renderer, const Setting& s, std::uint64_t& rays, double& seconds) const {
        renderer.clear_radiance_cache();
        std::uint64_t id = 1;
        for (int k = s.warm; k > 0; --k) {
            renderer.begin_frame(at(30 - static_cast<std::size_t>(k), id++, s));
            RgbFloatImage warm(renderer.render_size());
            (void)renderer.render(PixelRect::whole(warm.size), warm);
        }
        RgbFloatImage sum;
        for (int f = 0; f < s.frames_averaged; ++f) {
            renderer.begin_frame(at(30, id++, s));
            RgbFloatImage frame(renderer.render_size());
            const double t0 = thread_cpu_seconds();
            rays = renderer.render(PixelRect::whole(frame.size), frame).rays;
            if (f == 0) seconds = thread_cpu_seconds() - t0;
            if (f == 0) {
                sum = frame;
            } else {
                for (std::size_t i = 0; i < sum.pixels.size(); ++i) sum.pixels[i] += frame.pixels[i];
            }
        }
        for (float& p : sum.pixels) p /= static_cast<float>(s.frames_averaged);
        return sum;
    }
};

std::vector<Setting> settings(int warm) {
    std::vector<Setting> out;
    const auto direct_traced = [](Setting s) {  // the same setting with no direct light from the cells
        s.cache_direct = false;
        return s;
    };
    for (const int spp : {1, 2, 4})
        out.push_back({"path tracer, " + std::to_string(spp) + " spp", "path-" + std::to_string(spp), false, spp});
    const std::string w = std::to_string(warm) + " warm frames";
    out.push_back({"cache, cold (no frame before)", "cache-cold", true, 1, 0});
    out.push_back({"cache, " + w +
                       " (defaults: 4 footprints, 1 in 16 trains, visibility 8 / 1 in 8, direct light from the cells)",
                   "cache", true, 1, warm});
    out.push_back(
        {"cache, " + w + ", every shadow ray traced (no visibility)", "cache-novis", true, 1, warm, 4.0f, 16, 1, 0});
    out.push_back(direct_traced({"cache, " + w + ", direct light traced at every pixel (none from the cells)",
                                 "cache-direct-traced", true, 1, warm}));
    out.push_back(
        {"cache, " + w + ", visibility after 12 agreeing rays", "cache-vis12", true, 1, warm, 4.0f, 16, 1, 12});
    out.push_back(
        {"cache, " + w + ", visibility rechecked 1 in 32", "cache-recheck32", true, 1, warm, 4.0f, 16, 1, 8, 32});
    out.push_back({"cache, " + w + ", 2 footprints", "cache-fp2", true, 1, warm, 2.0f});
    out.push_back({"cache, " + w + ", 8 footprints", "cache-fp8", true, 1, warm, 8.0f});
    out.push_back({"cache, " + w + ", 1 in 4 trains", "cache-train4", true, 1, warm, 4.0f, 4});
    out.push_back({"cache, " + w + ", 1 in 64 trains", "cache-train64", true, 1, warm, 4.0f, 64});
    out.push_back({"path tracer, 1 spp, mean of 16 frames", "path-mean16", false, 1, 0, 4.0f, 16, 16});
    out.push_back({"cache, " + w + ", mean of 16 frames, jittered (its bias)", "cache-mean16", true, 1, warm, 4.0f, 16,
                   16, 8, 8, true});
    out.push_back(direct_traced({"cache, " + w + ", direct light traced at every pixel, mean of 16 frames, jittered",
                                 "cache-direct-traced-mean16", true, 1, warm, 4.0f, 16, 16, 8, 8, true}));
    out.push_back({"cache, " + w + ", no visibility, mean of 16 frames, jittered", "cache-novis-mean16", true, 1, warm,
                   4.0f, 16, 16, 0, 8, true});
    out.push_back({"cache, " + w + ", mean of 16 frames at pixel centres (as served)", "cache-mean16-centres", true, 1,
                   warm, 4.0f, 16, 16});
    return out;
}

int run(int argc, char** argv) {
    const std::string scene_file = arg_str(argc, argv, "--scene", "scenes/grotto.json");
    SceneLoadOptions load;
    load.scans_dir = arg_str(argc, argv, "--scans", "");
    const Scene scene = load_scene(scene_file, load);
    Bench b{scene, make_camera_path("walk", scene.viewer, 60), {}, {}, {}};
    b.view.size = {arg_int(argc, argv, "--width", 480), arg_int(argc, argv, "--height", 270)};
    b.view.camera = CylinderScreen{3.0, 150.0, 0.2, 2.8, {0.0, 1.6, 0.0}};
    b.view.pose = b.path[30];
    b.view.quality.max_bounces = arg_int(argc, argv, "--bounces", 1);
    const int ref_spp = arg_int(argc, argv, "--ref-spp", 256);
    const int warm = std::clamp(arg_int(argc, argv, "--warm-frames", 10), 0, 30);
    const int reps = std::max(1, arg_int(argc, argv, "--reps", 2));
    const std::string png_dir = arg_str(argc, argv, "--png-dir", "");
    if (!png_dir.empty()) std::filesystem::create_directories(png_dir);
    const double load_start = bench::load_average();
    {
        Renderer reference_renderer(scene, RendererOptions{"threads=1"});
        b.reference = reference_frame(reference_renderer, b.view, ref_spp);
    }
    b.reference8 = b.display(b.reference);
    if (!png_dir.empty()) write_png(std::filesystem::path(png_dir) / "reference.png", b.reference8);

    const std::vector<Setting> all = settings(warm);
    std::vector<Row> rows(all.size());
    for (int r = 0; r < reps; ++r) {  // settings interleaved: drift on a shared machine hits them alike
        for (std::size_t i = 0; i < all.size(); ++i) {
            RendererOptions o{"threads=1"};
            o.radiance_cache.cell_footprints = all[i].cell_footprints;
            o.radiance_cache.train_one_in = all[i].train_one_in;
            o.radiance_cache.visibility_min_samples = all[i].visibility_min_samples;
            o.radiance_cache.visibility_recheck_one_in = all[i].visibility_recheck_one_in;
            o.jitter_cached_one_spp = all[i].jitter_cached;
            o.radiance_cache.cache_direct = all[i].cache_direct;
            Renderer renderer(scene, o);
            std::uint64_t rays = 0;
            double seconds = 0.0;
            const RgbFloatImage frame = b.draw(renderer, all[i], rays, seconds);
            rows[i].seconds = std::min(rows[i].seconds, seconds);
            rows[i].rays_per_pixel = static_cast<double>(rays) / static_cast<double>(frame.size.pixel_count());
            rows[i].relmse = quality::relative_mse(frame, b.reference);
            const Rgb8Image shown = b.display(frame);
            rows[i].gmsd = quality::gmsd(shown, b.reference8);
            if (r == 0 && !png_dir.empty()) write_png(std::filesystem::path(png_dir) / (all[i].png + ".png"), shown);
        }
    }
    std::ostringstream md;
    md << "_Run " << bench::run_context() << ", load average " << fmt("%.2f", load_start) << " at start, "
       << fmt("%.2f", bench::load_average()) << " at end. " << scene_file << ", " << b.view.size.width << "x"
       << b.view.size.height << " cylinder `walk` view (pose 30 of 60), " << b.view.quality.max_bounces
       << " bounce(s), one thread, best of " << reps << "; reference " << ref_spp
       << " spp. Regenerate: `build/bench/mogao_bench_radiance_cache --scans ../shared/data/scans --write-docs "
          "docs/renderer.md`._\n\n"
       << "| setting | CPU s | time / path 1 spp | rays per pixel | relMSE | relMSE path 1 spp / setting | GMSD |\n"
          "|--|--:|--:|--:|--:|--:|--:|\n";
    for (std::size_t i = 0; i < all.size(); ++i) {
        const Row& p = rows[i];
        md << "| " << all[i].label << " | " << fmt("%.3g", p.seconds) << " | "
           << fmt("%.3f", p.seconds / rows[0].seconds) << " | " << fmt("%.2f", p.rays_per_pixel) << " | "
           << fmt("%.4g", p.relmse) << " | " << fmt("%.2f", rows[0].relmse / p.relmse) << " | " << fmt("%.4f", p.gmsd)
           << " |\n";
    }
    bench::print_and_write_block(argc, argv, "radiance-cache", md.str());
    return 0;
}

}  // namespace

int main(int argc, char** argv) { return mogao::bench::run_main("mogao_bench_radiance_cache", run, argc, argv); }
