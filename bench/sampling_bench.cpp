// SPDX-License-Identifier: Apache-2.0
// Cheaper and better samples, as time against error: Russian roulette (RendererOptions::
// russian_roulette), the Sobol' sub-pixel position at 1 spp (RendererOptions::jitter_one_spp) and the
// environment taken from escaping bounce rays (RendererOptions::environment_from_bounce), each against
// the former setting measured in the same run (ratios are meaningful on any machine, absolute times
// are not).
//
//   mogao_bench_sampling [--scene scenes/grotto.json] [--scans DIR] [--width 240] [--height 135]
//                        [--bounces 6] [--ref-spp 256] [--max-spp 16] [--passes 16] [--reps 2]
//                        [--write-docs docs/renderer.md] [--png-dir DIR]
//
// View: the scene's `walk` path, pose 30 of 60, on the grotto's cylinder screen (as mogao_bench_render
// (d)), --bounces bounces, one thread. Error: relMSE of linear radiance (bench/quality/image_metrics.h,
// eps 1e-2) against a converged reference of the same view (--ref-spp samples, roulette off, another
// seed, rendered on every core). Times: the render thread's CPU time, best of --reps, the settings
// interleaved so that drift on a shared machine affects them alike.
//  (1) equal spp: time, rays per sample and relMSE at spp 1, 2, 4, ..., --max-spp for
//      before (pixel centre at 1 spp, no roulette, the environment's own ray at every vertex), roulette
//      alone, the 1-spp position alone, the environment from the bounce alone, all three; at spp > 1
//      the position setting changes nothing (the pixel's samples are a Sobol' net either way), so
//      those cells are the same render and are measured once;
//  (2) equal time: each setting's relMSE interpolated log-log at the before-setting's times, and
//      the ratio before/setting (> 1: the setting has the smaller error at equal time);
//  (3) --passes one-spp frames accumulated over frame ids (what the farm does for a still view):
//      pixel centres converge to a point-sampled image, Sobol' positions to the area average.
// --write-docs FILE replaces the block between `<!-- generated:sampling -->` and `<!-- /generated -->`
// in FILE with the run's line (date, commit, CPU, load average) and the tables. --png-dir DIR writes
// the reference, the 1-spp frames of each setting and the accumulated passes (the scene's exposure
// and tone map), to look at.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "bench/quality/bench_report.h"
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
using bench::load_average;
using bench::reference_frame;

struct Setting {
    const char* label;
    const char* png;  // --png-dir file of its 1-spp frame
    bool roulette;
    bool jitter;
    bool environment_from_bounce;
};
constexpr std::array<Setting, 5> kSettings = {{
    {"before: pixel centre at 1 spp, no roulette, sky's own ray", "one-spp-before", false, false, false},
    {"Russian roulette", "one-spp-roulette", true, false, false},
    {"Sobol' position at 1 spp", "one-spp-sobol", false, true, false},
    {"environment from the bounce", "one-spp-sky-bounce", false, false, true},
    {"all three (defaults)", "one-spp-defaults", true, true, true},
}};

RendererOptions options_of(const Setting& s) {
    RendererOptions o;
    o.russian_roulette = s.roulette;
    o.jitter_one_spp = s.jitter;
    o.environment_from_bounce = s.environment_from_bounce;
    return o;
}

// The setting whose render setting s is at `spp`: above 1 spp the first one that differs from it at most by
// the 1-spp position (the same render).
std::size_t rendered_as(std::size_t s, int spp) {
    if (spp == 1) return s;
    for (std::size_t c = 0; c < kSettings.size(); ++c) {
        if (kSettings[c].roulette == kSettings[s].roulette &&
            kSettings[c].environment_from_bounce == kSettings[s].environment_from_bounce)
            return c;
    }
    return s;
}

struct Point {
    int spp = 0;
    double seconds = 1e300;
    double rays_per_sample = 0.0;
    double relmse = 0.0;
};

RgbFloatImage render_once(Renderer& renderer, const ViewRequest& view, std::uint64_t& rays) {
    renderer.begin_frame(view);
    RgbFloatImage frame(renderer.render_size());
    rays = renderer.render(PixelRect::whole(frame.size), frame).rays;
    return frame;
}

// Writes `frame` as DIR/NAME.png with the scene's exposure and tone map; nothing when dir is empty.
void save_png(const std::string& dir, const char* name, const RgbFloatImage& frame, const Scene& scene) {
    if (dir.empty()) return;
    Rgb8Image out(frame.size);
    to_srgb8(frame, PixelRect::whole(frame.size), scene.exposure, out, scene.tone_map);
    write_png(std::filesystem::path(dir) / (std::string(name) + ".png"), out);
}

// (1): curves[setting][k] at spp 2^k; above 1 spp a setting that differs from an earlier one only by the
// 1-spp position copies it (rendered_as: the same render).
std::vector<std::vector<Point>> equal_spp(Renderer& renderer, const ViewRequest& view, const RgbFloatImage& reference,
                                          int max_spp, int reps, const Scene& scene, const std::string& png_dir) {
    std::vector<std::vector<Point>> curves(kSettings.size());
    for (int spp = 1; spp <= max_spp; spp *= 2) {
        ViewRequest v = view;
        v.quality.spp = spp;
        std::vector<Point> row(kSettings.size());
        for (int r = 0; r < std::max(1, reps); ++r) {
            for (std::size_t s = 0; s < kSettings.size(); ++s) {
                if (rendered_as(s, spp) != s) continue;
                renderer.set_path_options(options_of(kSettings[s]));
                renderer.begin_frame(v);
                RgbFloatImage frame(renderer.render_size());
                const double t0 = thread_cpu_seconds();
                const std::uint64_t rays = renderer.render(PixelRect::whole(frame.size), frame).rays;
                row[s].seconds = std::min(row[s].seconds, thread_cpu_seconds() - t0);
                row[s].spp = spp;
                row[s].rays_per_sample =
                    static_cast<double>(rays) / (static_cast<double>(frame.size.pixel_count()) * spp);
                row[s].relmse = quality::relative_mse(frame, reference);
                if (spp == 1 && r == 0) save_png(png_dir, kSettings[s].png, frame, scene);
            }
        }
        for (std::size_t s = 0; s < kSettings.size(); ++s) curves[s].push_back(row[rendered_as(s, spp)]);
    }
    return curves;
}

// log-log interpolation of relMSE at time t; NaN outside the curve's range.
double relmse_at(const std::vector<Point>& curve, double t) {
    for (std::size_t i = 0; i + 1 < curve.size(); ++i) {
        const Point& a = curve[i];
        const Point& b = curve[i + 1];
        if (t < a.seconds || t > b.seconds) continue;
        const double f = std::log(t / a.seconds) / std::log(b.seconds / a.seconds);
        return std::exp(std::log(a.relmse) + f * std::log(b.relmse / a.relmse));
    }
    if (!curve.empty() && t == curve.back().seconds) return curve.back().relmse;
    return std::nan("");
}

// (3): relMSE of the mean of `passes` one-spp frames (frame ids 0..passes-1), centred and jittered.
std::array<double, 2> accumulated_passes(Renderer& renderer, const ViewRequest& view, const RgbFloatImage& reference,
                                         int passes, const Scene& scene, const std::string& png_dir) {
    std::array<double, 2> out{};
    for (int jitter = 0; jitter < 2; ++jitter) {
        Setting setting = kSettings.back();  // the defaults, with the pixel centre or the Sobol' position
        setting.jitter = jitter == 1;
        renderer.set_path_options(options_of(setting));
        RgbFloatImage sum(reference.size, 0.0f);
        for (int p = 0; p < passes; ++p) {
            ViewRequest v = view;
            v.quality.spp = 1;
            v.frame_id = static_cast<std::uint64_t>(p);
            std::uint64_t rays = 0;
            const RgbFloatImage frame = render_once(renderer, v, rays);
            for (std::size_t i = 0; i < frame.pixels.size(); ++i)
                sum.pixels[i] += frame.pixels[i] / static_cast<float>(passes);
        }
        out[static_cast<std::size_t>(jitter)] = quality::relative_mse(sum, reference);
        save_png(png_dir, jitter == 0 ? "passes-centres" : "passes-sobol", sum, scene);
    }
    return out;
}

std::string spp_table(const std::vector<std::vector<Point>>& curves) {
    std::ostringstream md;
    md << "| spp | setting | CPU s | time / before | rays per sample | relMSE | relMSE before / setting |\n"
          "|--:|--|--:|--:|--:|--:|--:|\n";
    for (std::size_t k = 0; k < curves[0].size(); ++k)
        for (std::size_t s = 0; s < kSettings.size(); ++s) {
            const Point& p = curves[s][k];
            const Point& b = curves[0][k];
            md << "| " << p.spp << " | " << kSettings[s].label << " | " << fmt("%.3g", p.seconds) << " | "
               << fmt("%.3f", p.seconds / b.seconds) << " | " << fmt("%.2f", p.rays_per_sample) << " | "
               << fmt("%.4g", p.relmse) << " | " << fmt("%.3f", b.relmse / p.relmse) << " |\n";
        }
    return md.str();
}

std::string time_table(const std::vector<std::vector<Point>>& curves) {
    std::ostringstream md;
    md << "| CPU s (before's spp) | setting | relMSE before | relMSE setting | before / setting |\n"
          "|--:|--|--:|--:|--:|\n";
    for (const Point& b : curves[0])
        for (std::size_t s = 1; s < kSettings.size(); ++s) {
            const double e = relmse_at(curves[s], b.seconds);
            if (std::isnan(e)) continue;
            md << "| " << fmt("%.3g", b.seconds) << " (" << b.spp << ") | " << kSettings[s].label << " | "
               << fmt("%.4g", b.relmse) << " | " << fmt("%.4g", e) << " | " << fmt("%.3f", b.relmse / e) << " |\n";
        }
    return md.str();
}

int run(int argc, char** argv) {
    const std::string scene_file = arg_str(argc, argv, "--scene", "scenes/grotto.json");
    SceneLoadOptions load;
    load.scans_dir = arg_str(argc, argv, "--scans", "");
    const Scene scene = load_scene(scene_file, load);
    ViewRequest view;
    view.size = {arg_int(argc, argv, "--width", 240), arg_int(argc, argv, "--height", 135)};
    view.camera = CylinderScreen{3.0, 150.0, 0.2, 2.8, {0.0, 1.6, 0.0}};
    view.pose = make_camera_path("walk", scene.viewer, 60)[30];
    view.quality.max_bounces = arg_int(argc, argv, "--bounces", 6);
    const int ref_spp = arg_int(argc, argv, "--ref-spp", 256);
    const int passes = arg_int(argc, argv, "--passes", 16);
    const double load_start = load_average();
    Renderer renderer(scene, RendererOptions{"threads=1"});
    const std::string png_dir = arg_str(argc, argv, "--png-dir", "");
    if (!png_dir.empty()) std::filesystem::create_directories(png_dir);
    const RgbFloatImage reference = reference_frame(renderer, view, ref_spp);
    save_png(png_dir, "reference", reference, scene);
    const auto curves = equal_spp(renderer, view, reference, arg_int(argc, argv, "--max-spp", 16),
                                  arg_int(argc, argv, "--reps", 2), scene, png_dir);
    const std::array<double, 2> accumulated = accumulated_passes(renderer, view, reference, passes, scene, png_dir);

    std::ostringstream md;
    md << "_Run " << bench::run_context() << ", load average " << fmt("%.2f", load_start) << " at start, "
       << fmt("%.2f", load_average()) << " at end. " << scene_file << ", " << view.size.width << "x" << view.size.height
       << " cylinder `walk` view, " << view.quality.max_bounces << " bounces, one thread, best of "
       << arg_int(argc, argv, "--reps", 2) << "; reference " << ref_spp
       << " spp. Regenerate: `build/bench/mogao_bench_sampling --write-docs docs/renderer.md`._\n\n"
       << "Equal spp:\n\n"
       << spp_table(curves) << "\nEqual time (each setting's relMSE interpolated log-log at the before-setting's "
       << "CPU times):\n\n"
       << time_table(curves) << "\n"
       << passes << " one-spp passes accumulated over frame ids: relMSE pixel centres " << fmt("%.4g", accumulated[0])
       << ", Sobol' positions " << fmt("%.4g", accumulated[1]) << " (centres / Sobol' "
       << fmt("%.2f", accumulated[0] / accumulated[1]) << ").\n";
    bench::print_and_write_block(argc, argv, "sampling", md.str());
    return 0;
}

}  // namespace

int main(int argc, char** argv) { return mogao::bench::run_main("mogao_bench_sampling", run, argc, argv); }
