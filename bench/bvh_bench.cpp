// SPDX-License-Identifier: Apache-2.0
// BVH choices as build time, memory and traversal speed (BvhOptions, render_scene.h), each against
// today's default measured in the same run (ratios are meaningful on any machine, absolute times
// are not):
//
//   mogao_bench_bvh [--scene scenes/grotto.json] [--scans DIR] [--width 480] [--height 270]
//                   [--poses 4] [--reps 3] [--write-docs docs/renderer.md]
//
// Choices: one BLAS per mesh under a two-level TLAS (instanced), and the static instances flattened
// into one BLAS, each at Embree's high, medium and low build quality and with RTC_SCENE_FLAG_COMPACT.
// Views: --poses poses spread along the scene's `walk` path on the grotto's cylinder screen, 1 spp.
// Per choice: the BVH build (Renderer construction, wall seconds, one build thread), the bytes Embree
// holds (its memory monitor), raw Embree on the camera packets the renderer traces, and whole
// renders at 0, 1 and 6 bounces (the calling thread's CPU seconds summed over the poses, best of
// --reps, the choices interleaved so that drift on a shared machine affects them alike); and the
// relMSE of each choice's 1-bounce frames against the first choice's (same seeds: only float
// rounding of the hit points differs, so this must stay near 0).
// --write-docs FILE replaces the block between `<!-- generated:bvh -->` and `<!-- /generated -->`.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "bench/quality/bench_report.h"
#include "bench/quality/image_metrics.h"
#include "common/camera_path.h"
#include "common/thread_clock.h"
#include "renderfarm/scene/scene_file.h"
#include "renderfarm/trace/render_scene.h"
#include "renderfarm/trace/render_timing.h"
#include "renderfarm/trace/renderer.h"

namespace {

using namespace mogao;
using bench::arg_int;
using bench::arg_str;
using bench::fmt;

struct Choice {
    const char* label;
    bool flatten;
    RTCBuildQuality quality;
    bool compact;
};
constexpr std::array<Choice, 6> kChoices = {{
    {"instanced, high quality (before)", false, RTC_BUILD_QUALITY_HIGH, false},
    {"flattened, high quality (default)", true, RTC_BUILD_QUALITY_HIGH, false},
    {"flattened, medium quality", true, RTC_BUILD_QUALITY_MEDIUM, false},
    {"flattened, low quality", true, RTC_BUILD_QUALITY_LOW, false},
    {"flattened, high quality, compact", true, RTC_BUILD_QUALITY_HIGH, true},
    {"instanced, high quality, compact", false, RTC_BUILD_QUALITY_HIGH, true},
}};
constexpr std::array<int, 3> kBounces = {0, 1, 6};

struct Measured {
    double build_s = 0.0;
    double megabytes = 0.0;
    std::size_t flattened = 0;
    double camera_s = std::numeric_limits<double>::infinity();
    std::array<double, kBounces.size()> render_s{};
    double relmse = 0.0;  // 1-bounce frames against the first choice's
};

// One rep of every pose for `renderer`: the camera packets' and each bounce count's CPU seconds.
void time_poses(Renderer& renderer, const std::vector<ViewRequest>& views, Measured& m,
                std::vector<RgbFloatImage>* one_bounce) {
    double camera = 0.0;
    std::array<double, kBounces.size()> render{};
    for (std::size_t p = 0; p < views.size(); ++p) {
        for (std::size_t b = 0; b < kBounces.size(); ++b) {
            ViewRequest v = views[p];
            v.quality.max_bounces = kBounces[b];
            const RenderTimings t = time_frame(renderer, v, 1);
            render[b] += t.render_s;
            if (b == 0) camera += t.camera_rays_s;
            if (one_bounce && kBounces[b] == 1) {
                renderer.begin_frame(v);
                RgbFloatImage frame(renderer.render_size());
                (void)renderer.render(PixelRect::whole(frame.size), frame);
                (*one_bounce)[p] = std::move(frame);
            }
        }
    }
    m.camera_s = std::min(m.camera_s, camera);
    for (std::size_t b = 0; b < kBounces.size(); ++b)
        m.render_s[b] = m.render_s[b] == 0.0 ? render[b] : std::min(m.render_s[b], render[b]);
}

std::string table(const std::vector<Measured>& ms) {
    std::ostringstream md;
    md << "| BVH | instances flattened | build s | Embree MB | camera rays: time / before | render 0 bounces | "
          "1 bounce | 6 bounces | relMSE vs before |\n|--|--:|--:|--:|--:|--:|--:|--:|--:|\n";
    const Measured& base = ms.front();
    for (std::size_t c = 0; c < ms.size(); ++c) {
        const Measured& m = ms[c];
        md << "| " << kChoices[c].label << " | " << m.flattened << " | " << fmt("%.2f", m.build_s) << " | "
           << fmt("%.0f", m.megabytes) << " | " << fmt("%.3f", m.camera_s / base.camera_s);
        for (std::size_t b = 0; b < kBounces.size(); ++b) md << " | " << fmt("%.3f", m.render_s[b] / base.render_s[b]);
        md << " | " << fmt("%.2g", m.relmse) << " |\n";
    }
    md << "\nBefore's CPU seconds (summed over the poses): camera rays " << fmt("%.3f", base.camera_s);
    for (std::size_t b = 0; b < kBounces.size(); ++b)
        md << ", render at " << kBounces[b] << " bounces " << fmt("%.3f", base.render_s[b]);
    md << ".\n";
    return md.str();
}

int run(int argc, char** argv) {
    const std::string scene_file = arg_str(argc, argv, "--scene", "scenes/grotto.json");
    SceneLoadOptions load;
    load.scans_dir = arg_str(argc, argv, "--scans", "");
    const Scene scene = load_scene(scene_file, load);
    const int poses = std::max(1, arg_int(argc, argv, "--poses", 4));
    const int reps = std::max(1, arg_int(argc, argv, "--reps", 3));
    std::vector<ViewRequest> views;
    const auto path = make_camera_path("walk", scene.viewer, 60);
    for (int p = 0; p < poses; ++p) {
        ViewRequest view;
        view.size = {arg_int(argc, argv, "--width", 480), arg_int(argc, argv, "--height", 270)};
        view.camera = CylinderScreen{3.0, 150.0, 0.2, 2.8, {0.0, 1.6, 0.0}};
        view.pose = path[static_cast<std::size_t>((p * 60) / poses + 60 / (2 * poses))];
        views.push_back(view);
    }
    const double load_start = bench::load_average();
    std::vector<std::unique_ptr<Renderer>> renderers;
    std::vector<Measured> ms(kChoices.size());
    for (std::size_t c = 0; c < kChoices.size(); ++c) {
        RendererOptions o{"threads=1"};
        o.bvh.flatten = kChoices[c].flatten;
        o.bvh.quality = kChoices[c].quality;
        o.bvh.compact = kChoices[c].compact;
        const auto t0 = std::chrono::steady_clock::now();
        renderers.push_back(std::make_unique<Renderer>(scene, o));
        ms[c].build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        ms[c].megabytes = static_cast<double>(renderers.back()->render_scene().bvh_bytes()) / (1024.0 * 1024.0);
        ms[c].flattened = renderers.back()->render_scene().flattened_instances();
    }
    std::vector<std::vector<RgbFloatImage>> frames(kChoices.size(), std::vector<RgbFloatImage>(views.size()));
    for (int r = 0; r < reps; ++r)
        for (std::size_t c = 0; c < kChoices.size(); ++c)
            time_poses(*renderers[c], views, ms[c], r == 0 ? &frames[c] : nullptr);
    for (std::size_t c = 0; c < kChoices.size(); ++c) {
        double sum = 0.0;
        for (std::size_t p = 0; p < views.size(); ++p) sum += quality::relative_mse(frames[c][p], frames[0][p]);
        ms[c].relmse = sum / static_cast<double>(views.size());
    }
    std::ostringstream md;
    md << "_Run " << bench::run_context() << ", load average " << fmt("%.2f", load_start) << " at start, "
       << fmt("%.2f", bench::load_average()) << " at end. " << scene_file << " (" << scene.instances.size()
       << " instances), " << views.front().size.width << "x" << views.front().size.height << " cylinder view at "
       << poses << " poses of the `walk` path, 1 spp, one thread, best of " << reps
       << ". Regenerate: `build/bench/mogao_bench_bvh --write-docs docs/renderer.md`._\n\n"
       << table(ms);
    bench::print_and_write_block(argc, argv, "bvh", md.str());
    return 0;
}

}  // namespace

int main(int argc, char** argv) { return mogao::bench::run_main("mogao_bench_bvh", run, argc, argv); }
