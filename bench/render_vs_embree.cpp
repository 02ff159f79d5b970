// SPDX-License-Identifier: Apache-2.0
// Renderer cost against raw Embree, measured in the same run (ratios are meaningful on any
// machine, absolute times are not):
//   (a) Embree alone: generate + rtcIntersect16 the camera packets the renderer traces;
//   (b) the full renderer with direct light and shadows (sun + its shadow rays);
//   (c) "model only what the scene requires": a sun without shadows and nothing else, vs the same
//       scene carrying present-but-unused features (zero-power area/point/environment lights,
//       an uninstanced mesh, a zero-specular material), vs a shadowing sun plus a used area light;
//       (c4) an unplaced mesh with vertex colours and a texture, (c5) the field carrying them.
// The scene is built in code: a ~1M-triangle smooth height field plus a sphere.
//   (d) with --scene FILE (e.g. scenes/grotto.json): the path speed-ups on a real scene, the
//       grotto's cylinder view at --scene-width x --scene-height (960x540), 1 spp: for today's path
//       (every RendererOptions switch off), each part alone, the defaults and everything on, the
//       renderer's Mrays/s, raw Embree tracing the same ray mix with
//       no shading (the camera packets plus the secondary rays that very render traced, recorded
//       and replayed as it traced them: packets or single rays), renderer/Embree throughput, the
//       frame time ratio new/legacy, and the PSNR of each 1 spp frame (sRGB8, the scene's exposure
//       and tone map) against a converged reference (--ref-spp, default 64, legacy estimator,
//       rendered on all cores), so speed is never bought with error.
//   (e) after (c), or after (d) with --scene: the same view at 0, 1, 2 and 6 bounces: the renderer
//       against raw Embree on exactly its ray mix (camera packets + the recorded secondary rays,
//       replayed as traced), the whole render with the former COHERENT light shadow packets over
//       the defaults (INCOHERENT) and whether their pixels are bit-identical, and the recorded
//       secondary rays replayed in each shape (packets with either flag, 1M streams, single rays).
// Usage: mogao_bench_render [--width W] [--height H] [--spp N] [--reps N] [--grid N] [--json FILE]
//                           [--scene FILE [--scans DIR] [--scene-width W] [--scene-height H] [--ref-spp N]]
// The table goes to stdout; --json FILE also writes every figure as JSON (for bench/regenerate-docs).
// Timings use Renderer/RenderTimings from renderfarm/trace/render_timing.h, which the farm can
// reuse on a real scene: time_render_vs_embree(scene, request).
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <limits>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/camera_path.h"
#include "common/thread_clock.h"
#include "renderfarm/scene/procedural.h"
#include "renderfarm/scene/scene.h"
#include "renderfarm/scene/scene_file.h"
#include "renderfarm/trace/film.h"
#include "renderfarm/trace/render_timing.h"
#include "renderfarm/trace/renderer.h"

namespace {

using namespace mogao;

// Height field y = h(x, z) over [-10, 10]² with n x n cells (2 n² triangles), analytic normals.
Mesh height_field(int n) {
    Mesh mesh;
    mesh.source = "height_field";
    const auto height = [](double x, double z) {
        return 0.4 * std::sin(1.3 * x) * std::cos(0.9 * z) + 0.1 * std::sin(4.0 * x + 3.0 * z);
    };
    const double half = 10.0;
    const double step = 2.0 * half / n;
    for (int j = 0; j <= n; ++j) {
        for (int i = 0; i <= n; ++i) {
            const double x = -half + step * i;
            const double z = -half + step * j;
            const double e = 1e-4;
            const double dx = (height(x + e, z) - height(x - e, z)) / (2 * e);
            const double dz = (height(x, z + e) - height(x, z - e)) / (2 * e);
            mesh.positions.emplace_back(static_cast<float>(x), static_cast<float>(height(x, z)), static_cast<float>(z));
            mesh.normals.push_back(Eigen::Vector3d(-dx, 1.0, -dz).normalized().cast<float>());
        }
    }
    const auto index = [n](int i, int j) { return static_cast<std::uint32_t>(j * (n + 1) + i); };
    for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
            mesh.triangles.push_back({index(i, j), index(i, j + 1), index(i + 1, j)});
            mesh.triangles.push_back({index(i + 1, j), index(i, j + 1), index(i + 1, j + 1)});
        }
    }
    return mesh;
}

// Matte height field + sphere, one sun; no other lights.
Scene base_scene(int grid, bool sun_shadows) {
    Scene scene;
    scene.source = "bench:height_field+sphere";
    scene.meshes = {height_field(grid), make_uv_sphere(1.0, 128, 64)};
    Material ground;
    ground.albedo = Rgb(0.55f, 0.5f, 0.4f);
    Material ball;
    ball.albedo = Rgb(0.3f, 0.4f, 0.7f);
    scene.materials = {ground, ball};
    Instance field{"field", 0, 0, Eigen::Affine3d::Identity()};
    Instance ball_instance{"ball", 1, 1, Eigen::Affine3d::Identity()};
    ball_instance.object_to_world.translate(Eigen::Vector3d(0.0, 1.5, -3.0));
    scene.instances = {field, ball_instance};
    DirectionalLight sun;
    sun.direction_to_light = Eigen::Vector3d(-0.5, 0.8, 0.3).normalized();
    sun.cast_shadows = sun_shadows;
    scene.directional_lights = {sun};
    return scene;
}

// Features present in the scene description but contributing nothing.
Scene with_unused_features(Scene scene) {
    scene.area_lights = {AreaLight{{-1.0, 4.0, -4.0}, {2.0, 0.0, 0.0}, {0.0, 0.0, 2.0}, Rgb(0.0f, 0.0f, 0.0f), true}};
    scene.point_lights = {PointLight{{0.0, 3.0, 0.0}, Rgb(0.0f, 0.0f, 0.0f), true}};
    scene.environment_lights = {EnvironmentLight{Rgb(0.0f, 0.0f, 0.0f)}};
    scene.meshes.push_back(make_uv_sphere(1.0, 64, 32));  // never instanced
    Material unused_glossy;
    unused_glossy.specular = Rgb(0.5f, 0.5f, 0.5f);  // no instance uses it
    scene.materials.push_back(unused_glossy);
    return scene;
}

// A copy of mesh `m` carrying vertex colours, uvs and a 256² texture (what a painted scan has).
Mesh with_colour(Mesh mesh) {
    auto texture = std::make_shared<Texture>();
    texture->source = "bench:checker";
    texture->image = Rgb8Image({256, 256});
    for (int y = 0; y < 256; ++y)
        for (int x = 0; x < 256; ++x)
            for (int c = 0; c < 3; ++c)
                texture->image.at(x, y)[c] = static_cast<std::uint8_t>(((x / 16 + y / 16) % 2) ? 230 : 60 + 40 * c);
    texture->mips = make_mip_chain(texture->image);  // as a loaded texture has: trilinear lookups
    for (const Eigen::Vector3f& p : mesh.positions) {
        mesh.colors.emplace_back(0.9f, 0.8f, 0.7f);
        mesh.uvs.emplace_back(0.1f * p.x(), 0.1f * p.z());
    }
    mesh.texture = texture;
    return mesh;
}

// Colour and texture present but unused: a coloured, textured mesh no instance places.
Scene with_unused_colour(Scene scene) {
    scene.meshes.push_back(with_colour(scene.meshes[0]));
    return scene;
}

// Colour and texture used: the height field carries them.
Scene with_used_colour(Scene scene) {
    scene.meshes[0] = with_colour(scene.meshes[0]);
    return scene;
}

Scene with_used_area_light(Scene scene) {
    scene.area_lights = {AreaLight{{-1.0, 4.0, -4.0}, {2.0, 0.0, 0.0}, {0.0, 0.0, 2.0}, Rgb(4.0f, 4.0f, 4.0f), true}};
    return scene;
}

int arg_int(int argc, char** argv, const char* name, int fallback) {
    for (int i = 1; i + 1 < argc; ++i) {
        if (std::strcmp(argv[i], name) == 0) return std::atoi(argv[i + 1]);
    }
    return fallback;
}

const char* arg_str(int argc, char** argv, const char* name, const char* fallback) {
    for (int i = 1; i + 1 < argc; ++i) {
        if (std::strcmp(argv[i], name) == 0) return argv[i + 1];
    }
    return fallback;
}

nlohmann::json timing_json(const char* label, const RenderTimings& t) {
    return {{"label", label},
            {"embree_camera_ms", 1e3 * t.camera_rays_s},
            {"embree_camera_rays", t.camera_rays},
            {"renderer_ms", 1e3 * t.render_s},
            {"renderer_rays", t.render_rays},
            {"renderer_mrays_per_s", 1e-6 * static_cast<double>(t.render_rays) / t.render_s},
            {"renderer_vs_embree", t.ratio()},
            {"bvh_build_s", t.build_s}};
}

void print(const char* label, const RenderTimings& t, double baseline_s) {
    std::printf("%-44s %9.2f ms  %11llu rays  %6.2f Mrays/s  x%.2f vs (a)\n", label, 1e3 * t.render_s,
                static_cast<unsigned long long>(t.render_rays), 1e-6 * static_cast<double>(t.render_rays) / t.render_s,
                t.render_s / baseline_s);
}

// One path of (d): its frame, CPU time, rays, and raw Embree on the same ray mix.
struct PathFigures {
    RgbFloatImage frame;
    double render_s = 1e300;
    double embree_s = 1e300;
    std::uint64_t rays = 0;
    std::uint64_t embree_rays = 0;
    double psnr_db = 0.0;
    [[nodiscard]] double mrays() const { return 1e-6 * static_cast<double>(rays) / render_s; }
    [[nodiscard]] double embree_mrays() const { return 1e-6 * static_cast<double>(embree_rays) / embree_s; }
};

PathFigures time_path(Renderer& renderer, const ViewRequest& view, const RendererOptions& options, int reps) {
    renderer.set_path_options(options);
    renderer.begin_frame(view);
    PathFigures f;
    f.frame = RgbFloatImage(renderer.render_size());
    const PixelRect whole = PixelRect::whole(f.frame.size);
    RecordedRays log;
    f.rays = renderer.render_recording(whole, f.frame, log).rays;
    for (int r = 0; r < std::max(1, reps); ++r) {
        double t0 = thread_cpu_seconds();
        (void)renderer.render(whole, f.frame);
        f.render_s = std::min(f.render_s, thread_cpu_seconds() - t0);
        t0 = thread_cpu_seconds();
        f.embree_rays = renderer.trace_camera_rays(whole).rays + renderer.trace_recorded(log).rays;
        f.embree_s = std::min(f.embree_s, thread_cpu_seconds() - t0);
    }
    return f;
}

// The converged reference, rendered in row bands on every hardware thread.
RgbFloatImage reference_frame(Renderer& renderer, ViewRequest view, int spp) {
    RendererOptions legacy;
    legacy.legacy_light_sampling = true;
    renderer.set_path_options(legacy);
    view.quality.spp = spp;
    renderer.begin_frame(view);
    RgbFloatImage frame(renderer.render_size());
    const int threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
    const int band = 8;
    std::atomic<int> next{0};
    const auto work = [&] {
        for (int y0 = band * next++; y0 < frame.size.height; y0 = band * next++) {
            (void)renderer.render(PixelRect{0, y0, frame.size.width, std::min(frame.size.height, y0 + band)}, frame);
        }
    };
    std::vector<std::jthread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(work);
    work();
    return frame;
}

// PSNR of 8-bit images over all samples, 10 log10(255² / MSE) (dB; +inf when identical).
double psnr(const Rgb8Image& a, const Rgb8Image& b) {
    double sum = 0.0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) {
        const double d = static_cast<double>(a.pixels[i]) - static_cast<double>(b.pixels[i]);
        sum += d * d;
    }
    const double mse = sum / static_cast<double>(a.pixels.size());
    return mse > 0.0 ? 10.0 * std::log10(255.0 * 255.0 / mse) : std::numeric_limits<double>::infinity();
}

Rgb8Image display(const RgbFloatImage& in, const Scene& scene) {
    Rgb8Image out(in.size);
    to_srgb8(in, PixelRect::whole(in.size), scene.exposure, out, scene.tone_map);
    return out;
}

void print_path(const char* label, const PathFigures& f, const PathFigures& legacy) {
    std::printf(
        "%-52s %8.1f ms %10llu rays %6.2f Mrays/s | Embree same mix %6.2f Mrays/s | renderer/Embree %.2f | "
        "time/legacy %.3f | PSNR %.2f dB\n",
        label, 1e3 * f.render_s, static_cast<unsigned long long>(f.rays), f.mrays(), f.embree_mrays(),
        f.mrays() / f.embree_mrays(), f.render_s / legacy.render_s, f.psnr_db);
}

// (e): one bounce count's figures (see the header comment).
struct BounceRow {
    int bounces = 0;
    std::uint64_t rays = 0;
    double render_s = 1e300;      // defaults: every secondary ray INCOHERENT
    double baseline_s = 1e300;    // light shadow packets COHERENT, as before the ray-flag audit
    double camera_s = 1e300;      // raw Embree: the camera packets
    bool identical = false;       // the two renders' pixels, bit for bit
    std::vector<double> shape_s;  // raw Embree: the recorded secondary rays in each shape of kShapes
    [[nodiscard]] double embree_s() const { return camera_s + shape_s[1]; }  // kAsRecorded of the defaults
};

struct Shape {
    const char* key;
    const char* label;
    ReplayShape shape;
    bool baseline_log;  // replays the baseline's log (its flags), not the defaults'
};
const std::array<Shape, 6> kShapes = {{
    {"coherent_lights_as_before", "packets, light shadows COHERENT (before)", ReplayShape::kAsRecorded, true},
    {"incoherent_packets", "packets, all INCOHERENT (defaults)", ReplayShape::kAsRecorded, false},
    {"coherent_first_hit", "packets, COHERENT at the first hit only", ReplayShape::kCoherentFirstHit, false},
    {"streams_coherent", "rtcOccluded1M/rtcIntersect1M, COHERENT", ReplayShape::kStreams, false},
    {"streams_incoherent", "rtcOccluded1M/rtcIntersect1M, INCOHERENT", ReplayShape::kIncoherentStreams, false},
    {"single_rays", "one ray at a time (rtcOccluded1/rtcIntersect1)", ReplayShape::kSingleRays, false},
}};

template <typename F>
void keep_min(double& best, F&& f) {
    const double t0 = thread_cpu_seconds();
    f();
    best = std::min(best, thread_cpu_seconds() - t0);
}

BounceRow time_bounces(Renderer& renderer, ViewRequest view, int bounces, int reps) {
    view.quality.max_bounces = bounces;
    RendererOptions baseline;
    baseline.coherent_shadow_packets_baseline = true;
    BounceRow row;
    row.bounces = bounces;
    row.shape_s.assign(kShapes.size(), 1e300);
    renderer.set_path_options(RendererOptions{});
    renderer.begin_frame(view);
    RgbFloatImage frame(renderer.render_size());
    RgbFloatImage old_frame(renderer.render_size());
    const PixelRect whole = PixelRect::whole(frame.size);
    RecordedRays log;
    RecordedRays baseline_log;
    row.rays = renderer.render_recording(whole, frame, log).rays;
    renderer.set_path_options(baseline);
    renderer.begin_frame(view);
    (void)renderer.render_recording(whole, old_frame, baseline_log);
    row.identical = frame.pixels == old_frame.pixels;
    for (int r = 0; r < std::max(1, reps); ++r) {  // interleaved, so that drift affects all alike
        renderer.set_path_options(baseline);
        renderer.begin_frame(view);
        keep_min(row.baseline_s, [&] { (void)renderer.render(whole, old_frame); });
        renderer.set_path_options(RendererOptions{});
        renderer.begin_frame(view);
        keep_min(row.render_s, [&] { (void)renderer.render(whole, frame); });
        keep_min(row.camera_s, [&] { (void)renderer.trace_camera_rays(whole); });
        for (std::size_t k = 0; k < kShapes.size(); ++k) {
            const RecordedRays& l = kShapes[k].baseline_log ? baseline_log : log;
            keep_min(row.shape_s[k], [&] { (void)renderer.trace_recorded(l, kShapes[k].shape); });
        }
    }
    return row;
}

// (e): renderer vs raw Embree on the same ray mix at 0, 1, 2 and 6 bounces, and the ray flags'
// and shapes' cost on the recorded secondary rays, all in one run.
nlohmann::json bounce_section(Renderer& renderer, const ViewRequest& view, int reps, const std::string& scene) {
    renderer.set_path_options(RendererOptions{});
    renderer.begin_frame(view);
    const ImageSize size = renderer.render_size();
    std::printf("(e) %s, %dx%d, %d spp, one thread, best of %d: bounces vs raw Embree on the same ray mix\n",
                scene.c_str(), size.width, size.height, view.quality.spp, reps);
    nlohmann::json rows = nlohmann::json::array();
    for (const int bounces : {0, 1, 2, 6}) {
        const BounceRow row = time_bounces(renderer, view, bounces, reps);
        std::printf(
            "  %d bounces: %10llu rays  renderer %8.1f ms  Embree same mix %8.1f ms  renderer/Embree throughput "
            "%.2f (goal >= 0.60)  before/now %.2f  pixels identical %s\n",
            bounces, static_cast<unsigned long long>(row.rays), 1e3 * row.render_s, 1e3 * row.embree_s(),
            row.embree_s() / row.render_s, row.baseline_s / row.render_s, row.identical ? "yes" : "NO");
        nlohmann::json shapes = nlohmann::json::object();
        for (std::size_t k = 0; k < kShapes.size(); ++k) {
            std::printf("      secondary rays as %-50s %8.1f ms  x%.2f vs defaults\n", kShapes[k].label,
                        1e3 * row.shape_s[k], row.shape_s[k] / row.shape_s[1]);
            shapes[kShapes[k].key] = 1e3 * row.shape_s[k];
        }
        rows.push_back({{"bounces", bounces},
                        {"rays", row.rays},
                        {"renderer_ms", 1e3 * row.render_s},
                        {"coherent_baseline_ms", 1e3 * row.baseline_s},
                        {"embree_same_mix_ms", 1e3 * row.embree_s()},
                        {"embree_camera_ms", 1e3 * row.camera_s},
                        {"renderer_vs_embree_throughput", row.embree_s() / row.render_s},
                        {"speedup_over_coherent", row.baseline_s / row.render_s},
                        {"pixels_identical", row.identical},
                        {"secondary_ms", shapes}});
    }
    return {{"scene", scene}, {"width", size.width}, {"height", size.height}, {"spp", view.quality.spp},
            {"reps", reps},   {"threads", 1},        {"rows", rows}};
}

// (d): see the header comment.
nlohmann::json scene_section(int argc, char** argv, int reps) {
    SceneLoadOptions load;
    load.scans_dir = arg_str(argc, argv, "--scans", "");
    const Scene scene = load_scene(arg_str(argc, argv, "--scene", ""), load);
    ViewRequest view;
    view.size = {arg_int(argc, argv, "--scene-width", 960), arg_int(argc, argv, "--scene-height", 540)};
    view.camera = CylinderScreen{3.0, 150.0, 0.2, 2.8, {0.0, 1.6, 0.0}};
    view.pose = make_camera_path("walk", scene.viewer, 60)[30];
    view.quality.spp = 1;
    const int ref_spp = arg_int(argc, argv, "--ref-spp", 64);
    Renderer renderer(scene, RendererOptions{"threads=1"});
    RendererOptions legacy_options;  // today's path: every switch off
    legacy_options.legacy_light_sampling = true;
    legacy_options.packet_secondary_rays = false;
    legacy_options.camera_column_table = false;
    legacy_options.native_packet_width = false;
    RendererOptions sampling_only = legacy_options;
    sampling_only.legacy_light_sampling = false;
    RendererOptions packets_only = legacy_options;
    packets_only.packet_secondary_rays = true;
    packets_only.native_packet_width = true;
    RendererOptions everything;
    everything.legacy_light_sampling = false;
    PathFigures legacy = time_path(renderer, view, legacy_options, reps);
    PathFigures sampling = time_path(renderer, view, sampling_only, reps);
    PathFigures packets = time_path(renderer, view, packets_only, reps);
    PathFigures current = time_path(renderer, view, RendererOptions{}, reps);
    PathFigures all = time_path(renderer, view, everything, reps);
    const Rgb8Image reference = display(reference_frame(renderer, view, ref_spp), scene);
    for (PathFigures* f : {&legacy, &sampling, &packets, &current, &all}) {
        f->psnr_db = psnr(display(f->frame, scene), reference);
    }
    std::printf("(d) %s, %zu instanced triangles, cylinder %dx%d, 1 spp, one thread, best of %d; reference %d spp\n",
                arg_str(argc, argv, "--scene", ""), scene.triangle_count(), view.size.width, view.size.height, reps,
                ref_spp);
    print_path("(d1) today: ray per light, single rays, emulated x16", legacy, legacy);
    print_path("(d2) (d1) + light selection + MIS", sampling, legacy);
    print_path("(d3) (d1) + native-width packets, secondary too", packets, legacy);
    print_path("(d4) defaults: (d3) + column table", current, legacy);
    print_path("(d5) (d4) + light selection + MIS", all, legacy);
    std::printf(
        "    frame time defaults/today = %.3f, renderer/Embree throughput defaults = %.2f (goal >= 0.60), "
        "PSNR defaults %.2f dB vs today %.2f dB\n",
        current.render_s / legacy.render_s, current.mrays() / current.embree_mrays(), current.psnr_db, legacy.psnr_db);
    const auto figures = [](const PathFigures& f) {
        return nlohmann::json{{"renderer_ms", 1e3 * f.render_s},
                              {"rays", f.rays},
                              {"renderer_mrays_per_s", f.mrays()},
                              {"embree_same_mix_mrays_per_s", f.embree_mrays()},
                              {"renderer_vs_embree_throughput", f.mrays() / f.embree_mrays()},
                              {"psnr_db", f.psnr_db}};
    };
    const nlohmann::json bounce_figures = bounce_section(renderer, view, reps, arg_str(argc, argv, "--scene", ""));
    return {{"scene", arg_str(argc, argv, "--scene", "")},
            {"e", bounce_figures},
            {"width", view.size.width},
            {"height", view.size.height},
            {"reps", reps},
            {"reference_spp", ref_spp},
            {"d1_legacy", figures(legacy)},
            {"d2_light_selection", figures(sampling)},
            {"d3_packets", figures(packets)},
            {"d4_new", figures(current)},
            {"d5_all", figures(all)},
            {"frame_time_new_over_legacy", current.render_s / legacy.render_s}};
}

void write_json(const std::string& path, const nlohmann::json& j) {
    std::ofstream file(path);
    file << j.dump(1) << '\n';
    if (!file.flush()) throw std::runtime_error("cannot write " + path);
}

// The synthetic scene's sections (a)-(c) and (e), printed; their figures as the JSON file's body.
nlohmann::json synthetic_section(const ViewRequest& request, const RendererOptions& options, int grid, int reps) {
    const Scene shadowed = base_scene(grid, true);
    std::printf("scene: %zu + %zu triangles, %dx%d, spp %d, best of %d, one thread\n",
                shadowed.meshes[0].triangle_count(), shadowed.meshes[1].triangle_count(), request.size.width,
                request.size.height, request.quality.spp, reps);
    Renderer renderer(shadowed, options);
    const RenderTimings direct = time_frame(renderer, request, reps);
    std::printf("(a) Embree rtcIntersect16, camera rays only    %9.2f ms  %11llu rays  %6.2f Mrays/s\n",
                1e3 * direct.camera_rays_s, static_cast<unsigned long long>(direct.camera_rays),
                1e-6 * static_cast<double>(direct.camera_rays) / direct.camera_rays_s);
    print("(b) renderer, sun + shadows", direct, direct.camera_rays_s);
    std::printf("    ratio (b)/(a) = %.2f\n", direct.ratio());

    // (c) Each variant gets its own (a) baseline from its own renderer, so ratios compare alike.
    const auto run = [&](const Scene& scene) { return time_render_vs_embree(scene, request, options, reps); };
    const RenderTimings plain = run(base_scene(grid, false));
    const RenderTimings unused = run(with_unused_features(base_scene(grid, false)));
    const RenderTimings used = run(with_used_area_light(base_scene(grid, true)));
    const RenderTimings colour_unused = run(with_unused_colour(base_scene(grid, false)));
    const RenderTimings colour_used = run(with_used_colour(base_scene(grid, false)));
    print("(c1) sun, no shadows, nothing else", plain, plain.camera_rays_s);
    print("(c2) (c1) + unused lights/mesh/material", unused, unused.camera_rays_s);
    print("(c3) sun + shadows + used area light", used, used.camera_rays_s);
    print("(c4) (c1) + unplaced coloured mesh", colour_unused, colour_unused.camera_rays_s);
    print("(c5) (c1), field coloured + textured", colour_used, colour_used.camera_rays_s);
    std::printf("    (c2)/(c1) = %.3f  (unused features should cost nothing: ~1.0)\n",
                unused.render_s / plain.render_s);
    std::printf("    (c3)/(c1) = %.3f  (what shadows and an area light cost when used)\n",
                used.render_s / plain.render_s);
    std::printf("    (c4)/(c1) = %.3f  (a scene without colour or texture pays nothing: ~1.0)\n",
                colour_unused.render_s / plain.render_s);
    std::printf("    (c5)/(c1) = %.3f  (what vertex colours and a mip-mapped texture cost when used)\n",
                colour_used.render_s / plain.render_s);
    std::printf("    BVH build (c1): %.2f s\n", plain.build_s);
    const nlohmann::json bounce_figures = bounce_section(renderer, request, reps, "in-code height field + sphere, sun");
    return {{"bench", "render_vs_embree"},
            {"triangles", shadowed.meshes[0].triangle_count() + shadowed.meshes[1].triangle_count()},
            {"width", request.size.width},
            {"height", request.size.height},
            {"spp", request.quality.spp},
            {"reps", reps},
            {"threads", 1},
            {"b", timing_json("renderer, sun + shadows", direct)},
            {"c1", timing_json("sun, no shadows, nothing else", plain)},
            {"c2", timing_json("(c1) + unused lights/mesh/material", unused)},
            {"c3", timing_json("sun + shadows + used area light", used)},
            {"ratio_b_over_a", direct.ratio()},
            {"ratio_c2_over_c1", unused.render_s / plain.render_s},
            {"ratio_c3_over_c1", used.render_s / plain.render_s},
            {"c4", timing_json("(c1) + an unplaced coloured, textured mesh", colour_unused)},
            {"c5", timing_json("(c1) with vertex colours + a texture", colour_used)},
            {"ratio_c4_over_c1", colour_unused.render_s / plain.render_s},
            {"ratio_c5_over_c1", colour_used.render_s / plain.render_s},
            {"e", bounce_figures}};
}

}  // namespace

int main(int argc, char** argv) {
    ViewRequest request;
    request.size = {arg_int(argc, argv, "--width", 640), arg_int(argc, argv, "--height", 360)};
    request.quality.spp = arg_int(argc, argv, "--spp", 1);
    const int reps = arg_int(argc, argv, "--reps", 5);
    const int grid = arg_int(argc, argv, "--grid", 708);  // 2 * 708² = 1.0M triangles
    request.pose.eye = {0.0, 3.0, 6.0};
    request.pose.pitch_deg = -20.0;
    request.camera = PinholeCamera{60.0};
    const RendererOptions options{"threads=1", true};
    const std::string json_file = arg_str(argc, argv, "--json", "");

    try {
        if (std::strlen(arg_str(argc, argv, "--scene", "")) > 0) {
            const nlohmann::json d = scene_section(argc, argv, reps);
            if (!json_file.empty()) write_json(json_file, {{"bench", "render_vs_embree_scene"}, {"d", d}});
            return 0;
        }
        const nlohmann::json out = synthetic_section(request, options, grid, reps);
        if (!json_file.empty()) write_json(json_file, out);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "mogao_bench_render: %s\n", e.what());
        return 1;
    }
    return 0;
}
