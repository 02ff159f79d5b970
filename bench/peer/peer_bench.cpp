// SPDX-License-Identifier: Apache-2.0
// Our side of the peer comparison with Blender Cycles (docs/quality.md, "A peer: Blender Cycles");
// bench/peer/run drives it and Blender.
//
//   mogao_peer_bench export    --out DIR [common flags]   scene.obj, scene.mtl, peer.json of the view
//   mogao_peer_bench ours      --out DIR --spp 1,4,16,64 [--reps 1] [--threads 1] [common flags]
//        renders the view at each spp (reference knobs: 6 bounces), writes DIR/ours-<spp>.pfm and prints
//        "spp,cpu_s,wall_s" rows, best of reps by CPU time (the BVH is built once before, not timed): on one
//        thread the rendering thread's CPU time; with --threads N, N threads take 16-row strips of the frame
//        in turn and cpu_s is the process's CPU time over the render; --window FILE writes "START END", the
//        CLOCK_MONOTONIC seconds around the renders, for a profile of them alone (bench/profile/run)
//   mogao_peer_bench reference --out DIR [--ref-spp 512] [--budget-s 600] [--cache-dir D] [--renderer-version V]
//        our converged reference of the view (bench/quality's cache and its two halves), DIR/ours-ref.pfm,
//        and prints its noise floor (relMSE of the reference against the truth, from its halves)
//   mogao_peer_bench compare   REF.pfm IMG.pfm...   prints "image,relmse,psnr_db,ssim" rows (image_metrics.h;
//        PSNR and SSIM on the scene's exposure and tone map)
// Common flags: [--scene scenes/grotto.json] [--scans DIR] [--view still|mask|room] [--width 120] (4:3 frame).
// Exits 77 when the scene needs the real scans and they are absent.
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "bench/peer/peer_export.h"
#include "bench/peer/pfm_io.h"
#include "bench/quality/image_metrics.h"
#include "bench/quality/reference_render.h"
#include "renderfarm/denoise/frame_error.h"
#include "renderfarm/scene/scene_file.h"
#include "renderfarm/trace/render_timing.h"

namespace {

using namespace mogao;
using namespace mogao::quality;

struct Options {
    std::string command;
    std::filesystem::path scene_file = std::filesystem::path(MOGAO_SOURCE_DIR) / "scenes" / "grotto.json";
    SceneLoadOptions load;
    std::string view = "still";
    int width = 120;
    std::vector<int> spp{1, 4, 16, 64};
    int reps = 1;
    int threads = 1;
    std::filesystem::path window;
    ReferencePlan plan;
    std::filesystem::path out_dir;
    std::vector<std::string> positional;
};

std::vector<int> split_ints(const std::string& text) {
    std::vector<int> values;
    std::stringstream in(text);
    for (std::string part; std::getline(in, part, ',');) values.push_back(std::stoi(part));
    return values;
}

Options parse(int argc, char** argv) {
    if (argc < 2) throw std::invalid_argument("usage: mogao_peer_bench export|ours|reference|compare [flags]");
    Options o;
    o.command = argv[1];
    o.plan.cache_dir = default_cache_dir();
    o.plan.renderer_version = "unversioned";
    o.plan.spp_per_half = 256;
    for (int i = 2; i < argc; ++i) {
        const std::string flag = argv[i];
        if (flag.rfind("--", 0) != 0) {
            o.positional.push_back(flag);
            continue;
        }
        if (i + 1 >= argc) throw std::invalid_argument("flag " + flag + " needs a value");
        const std::string v = argv[++i];
        if (flag == "--scene") o.scene_file = v;
        else if (flag == "--scans") o.load.scans_dir = v;
        else if (flag == "--view") o.view = v;
        else if (flag == "--width") o.width = std::stoi(v);
        else if (flag == "--spp") o.spp = split_ints(v);
        else if (flag == "--reps") o.reps = std::stoi(v);
        else if (flag == "--threads") o.threads = std::stoi(v);
        else if (flag == "--ref-spp") o.plan.spp_per_half = std::stoi(v) / 2;
        else if (flag == "--budget-s") o.plan.budget_seconds = std::stod(v);
        else if (flag == "--cache-dir") o.plan.cache_dir = v;
        else if (flag == "--renderer-version") o.plan.renderer_version = v;
        else if (flag == "--out") o.out_dir = v;
        else if (flag == "--window") o.window = v;
        else throw std::invalid_argument("unknown flag " + flag);
    }
    if (o.width < 16) throw std::invalid_argument("--width must be >= 16 (SSIM window)");
    if (o.plan.spp_per_half < 1) throw std::invalid_argument("--ref-spp must be >= 2");
    if (o.reps < 1) throw std::invalid_argument("--reps must be >= 1");
    if (o.threads < 1 || o.threads > 256) throw std::invalid_argument("--threads must be 1..256");
    o.plan.batch_spp = std::min(o.plan.batch_spp, o.plan.spp_per_half);
    if (o.command != "compare" && o.out_dir.empty()) throw std::invalid_argument("--out DIR is required");
    return o;
}

std::string read_text(const std::filesystem::path& file) {
    std::ifstream in(file);
    if (!in) throw std::runtime_error("cannot read " + file.string());
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

template <typename T>
T must(Result<T> r) {
    if (!r.ok()) throw std::runtime_error(r.error().message);
    return std::move(r).value();
}

void must(const Status& s) {
    if (!s.ok()) throw std::runtime_error(s.error().message);
}

QualityView find_view(const Scene& scene, const Options& o) {
    for (const QualityView& v : quality_views(scene, o.width, o.width))
        if (v.name == o.view) return v;
    throw std::invalid_argument("--view " + o.view + ": not one of bench/quality's views");
}

double process_cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double wall_seconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct ThreadedFrame {
    RgbFloatImage image;
    double cpu_s = 0.0;
    double wall_s = 0.0;
};

// The frame rendered by `threads` threads taking 16-row strips in turn (Renderer::render is safe on
// disjoint rects, renderer.h), the fastest of `reps` by the process's CPU time.
ThreadedFrame render_threaded(Renderer& renderer, const ViewRequest& request, int reps, int threads) {
    ThreadedFrame best;
    best.cpu_s = std::numeric_limits<double>::infinity();
    for (int r = 0; r < reps; ++r) {
        renderer.begin_frame(request);
        RgbFloatImage image(renderer.render_size());
        constexpr int kStrip = 16;
        std::atomic<int> next{0};
        const double cpu0 = process_cpu_seconds(), wall0 = wall_seconds();
        {
            std::vector<std::jthread> pool;
            for (int t = 0; t < threads; ++t) {
                pool.emplace_back([&] {
                    for (int y = next.fetch_add(kStrip); y < image.size.height; y = next.fetch_add(kStrip)) {
                        const PixelRect strip{0, y, image.size.width, std::min(image.size.height, y + kStrip)};
                        (void)renderer.render(strip, image);
                    }
                });
            }
        }
        const double cpu = process_cpu_seconds() - cpu0, wall = wall_seconds() - wall0;
        if (cpu < best.cpu_s) best = {std::move(image), cpu, wall};
    }
    return best;
}

void run_ours(const Options& o, const Scene& scene, const QualityView& view) {
    RendererOptions options;
    // The BVH build on as many threads as the render: the same CPU as Cycles' (its build is not timed either).
    options.embree_config = "threads=" + std::to_string(o.threads);
    Renderer renderer(scene, options);
    std::printf("spp,cpu_s,wall_s\n");
    // steady_clock is CLOCK_MONOTONIC on Linux, perf record -k mono's clock.
    const double start = wall_seconds();
    for (const int spp : o.spp) {
        ViewRequest r = reference_request(view);
        r.quality.spp = spp;
        r.seed = 1;  // the curves' seed, disjoint from the reference's
        ThreadedFrame f;
        if (o.threads == 1) {
            const double wall0 = wall_seconds();
            TimedFrame one = render_fastest_of(renderer, r, o.reps);
            f = {std::move(one.image), one.seconds, (wall_seconds() - wall0) / o.reps};
        } else {
            f = render_threaded(renderer, r, o.reps, o.threads);
        }
        must(peer::write_pfm(o.out_dir / ("ours-" + std::to_string(spp) + ".pfm"), f.image));
        std::printf("%d,%.6f,%.6f\n", spp, f.cpu_s, f.wall_s);
        std::fflush(stdout);
    }
    if (!o.window.empty()) {
        std::ofstream(o.window) << std::fixed << start << ' ' << wall_seconds() << '\n';
    }
}

void run_reference(const Options& o, const Scene& scene, const QualityView& view) {
    ReferencePlan plan = o.plan;
    plan.scene_text = read_text(o.scene_file);
    Renderer renderer(scene, RendererOptions{});
    const CachedReference ref = obtain_reference(renderer, view, plan);
    const ReferenceFloor f = reference_floor(ref, scene.exposure, scene.tone_map);
    must(peer::write_pfm(o.out_dir / "ours-ref.pfm", reference_image(ref)));
    must(peer::write_pfm(o.out_dir / "ours-ref-half-a.pfm", ref.half_a));
    must(peer::write_pfm(o.out_dir / "ours-ref-half-b.pfm", ref.half_b));
    std::printf("spp,seconds,floor_relmse,floor_psnr_db\n%d,%.1f,%.6g,%.3f\n", 2 * ref.spp_per_half, ref.seconds,
                f.floor_relmse, f.floor_psnr_db);
}

void run_compare(const Options& o, const Scene& scene) {
    if (o.positional.size() < 2) throw std::invalid_argument("compare needs REF.pfm and at least one IMG.pfm");
    const RgbFloatImage ref = must(peer::read_pfm(o.positional[0]));
    const Rgb8Image ref8 = display_frame(ref, scene.exposure, scene.tone_map);
    std::printf("image,relmse,psnr_db,ssim\n");
    for (std::size_t i = 1; i < o.positional.size(); ++i) {
        const RgbFloatImage img = must(peer::read_pfm(o.positional[i]));
        if (img.size.width != ref.size.width || img.size.height != ref.size.height)
            throw std::invalid_argument(o.positional[i] + ": size differs from " + o.positional[0]);
        const Rgb8Image img8 = display_frame(img, scene.exposure, scene.tone_map);
        std::printf("%s,%.6g,%.4f,%.5f\n", o.positional[i].c_str(), relative_mse(img, ref), display_psnr_db(img8, ref8),
                    ssim_luminance(img8, ref8));
    }
}

int run(const Options& o) {
    if (read_text(o.scene_file).find("{scans}") != std::string::npos &&
        !std::filesystem::exists(resolve_scans_dir(o.scene_file, o.load))) {
        std::printf("SKIP: real scans not found at %s\n", resolve_scans_dir(o.scene_file, o.load).c_str());
        return 77;
    }
    const Scene scene = load_scene(o.scene_file, o.load, nullptr);
    if (o.command == "compare") {
        run_compare(o, scene);
        return 0;
    }
    std::filesystem::create_directories(o.out_dir);
    const QualityView view = find_view(scene, o);
    if (o.command == "export") {
        const peer::ExportStats s = must(peer::write_obj(scene, o.out_dir));
        must(peer::write_peer_json(scene, view.request, o.out_dir));
        std::printf("exported %zu triangles, %zu vertices to %s\n", s.triangles, s.vertices, o.out_dir.c_str());
    } else if (o.command == "ours") {
        run_ours(o, scene, view);
    } else if (o.command == "reference") {
        run_reference(o, scene, view);
    } else {
        throw std::invalid_argument("unknown command " + o.command + " (export|ours|reference|compare)");
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return run(parse(argc, argv));
    } catch (const std::exception& e) {
        std::fprintf(stderr, "mogao_peer_bench: %s\n", e.what());
        return 1;
    }
}
