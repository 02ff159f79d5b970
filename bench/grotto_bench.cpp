// SPDX-License-Identifier: Apache-2.0
// The grotto with the real scans: what each quality knob costs in time and buys in error, what the
// renderer costs over raw Embree, and what lights cost only when the scene uses them. Every figure
// is a ratio against a baseline measured in the same run (absolute times depend on the machine).
//
//   mogao_bench_grotto [--scene scenes/grotto.json] [--scans DIR] [--width 320] [--height 180]
//                      [--reps 2] [--json FILE]
// (another --scene, e.g. scenes/test-room.json, makes a fast smoke run: bench/regenerate-docs --check)
//
// The markdown tables go to stdout; --json FILE also writes every figure as JSON (the input of
// bench/regenerate-docs, which fills docs/benchmarks.md).
//
// Error is measured against a reference render of the same view (spp 64, AO 16, 2 bounces, 8 area
// samples) as RMSE of linear radiance relative to the reference's mean, and as PSNR of the sRGB8
// frames. Times are the calling thread's CPU time, best of --reps. Exits 77 without the scans.
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/camera_path.h"
#include "common/image_compare.h"
#include "renderfarm/scene/scene_file.h"
#include "renderfarm/trace/film.h"
#include "renderfarm/trace/render_timing.h"
#include "renderfarm/trace/renderer.h"

namespace {

using namespace mogao;

// Nearest-neighbour upscale so a reduced-resolution frame can be compared with the reference.
RgbFloatImage upscale(const RgbFloatImage& in, ImageSize to) {
    RgbFloatImage out(to);
    for (int y = 0; y < to.height; ++y)
        for (int x = 0; x < to.width; ++x) {
            const int sx = std::min(in.size.width - 1, x * in.size.width / to.width);
            const int sy = std::min(in.size.height - 1, y * in.size.height / to.height);
            for (int c = 0; c < 3; ++c) out.at(x, y)[c] = in.at(sx, sy)[c];
        }
    return out;
}

Rgb8Image to_display(const RgbFloatImage& in, float exposure) {
    Rgb8Image out(in.size);
    to_srgb8(in, PixelRect::whole(in.size), exposure, out);
    return out;
}

double relative_rmse(const RgbFloatImage& a, const RgbFloatImage& reference) {
    double se = 0, sum = 0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) {
        const double d = double(a.pixels[i]) - double(reference.pixels[i]);
        se += d * d;
        sum += reference.pixels[i];
    }
    const double n = double(a.pixels.size());
    return std::sqrt(se / n) / (sum / n);
}

// Quality knobs: time against error, one knob at a time from the defaults; adds "reference",
// "baseline" and "knobs" to out.
void knobs_table(Renderer& renderer, const Scene& scene, const ViewRequest& view, int reps, nlohmann::json& out) {
    ViewRequest reference_view = view;
    reference_view.quality.spp = 64;
    reference_view.quality.ao_samples = 16;
    reference_view.quality.max_bounces = 2;
    reference_view.quality.area_light_samples = 8;
    const TimedFrame reference = render_fastest_of(renderer, reference_view, 1);
    const Rgb8Image reference_8 = to_display(reference.image, scene.exposure);
    ViewRequest base = view;
    base.quality.spp = 4;
    base.quality.ao_samples = 2;
    base.quality.max_bounces = 1;
    const TimedFrame base_frame = render_fastest_of(renderer, base, reps);
    std::printf(
        "## Quality knobs: time against error\n\nReference: spp 64, AO 16, 2 bounces, 8 area samples (%.1f s). "
        "Baseline: spp 4, AO 2, 1 bounce, 1 area sample, scale 1 (%.1f ms). One knob changes per row.\n\n",
        reference.seconds, 1e3 * base_frame.seconds);
    out["reference"] = {
        {"spp", 64}, {"ao_samples", 16}, {"max_bounces", 2}, {"area_light_samples", 8}, {"seconds", reference.seconds}};
    out["baseline"] = {{"spp", 4},
                       {"ao_samples", 2},
                       {"max_bounces", 1},
                       {"area_light_samples", 1},
                       {"resolution_scale", 1.0},
                       {"ms", 1e3 * base_frame.seconds}};
    out["knobs"] = nlohmann::json::array();
    std::printf(
        "| knob | value | CPU ms | time / baseline | relative RMSE | PSNR dB (sRGB8) |\n|---|--:|--:|--:|--:|--:|\n");
    const auto row = [&](const char* knob, const std::string& value, ViewRequest v) {
        const TimedFrame f = render_fastest_of(renderer, v, reps);
        const RgbFloatImage full =
            f.image.size == reference.image.size ? f.image : upscale(f.image, reference.image.size);
        const double rmse = relative_rmse(full, reference.image);
        const double db = psnr(to_display(full, scene.exposure), reference_8);
        std::printf("| %s | %s | %.1f | %.2f | %.4f | %.2f |\n", knob, value.c_str(), 1e3 * f.seconds,
                    f.seconds / base_frame.seconds, rmse, db);
        out["knobs"].push_back({{"knob", knob},
                                {"value", value},
                                {"ms", 1e3 * f.seconds},
                                {"time_vs_baseline", f.seconds / base_frame.seconds},
                                {"relative_rmse", rmse},
                                {"psnr_db", db}});
    };
    for (int spp : {1, 2, 4, 8, 16}) {
        ViewRequest v = base;
        v.quality.spp = spp;
        row("spp", std::to_string(spp), v);
    }
    for (int ao : {0, 1, 2, 4, 8}) {
        ViewRequest v = base;
        v.quality.ao_samples = ao;
        row("AO samples", std::to_string(ao), v);
    }
    for (int b : {0, 1, 2, 3}) {
        ViewRequest v = base;
        v.quality.max_bounces = b;
        row("max bounces", std::to_string(b), v);
    }
    for (int a : {1, 2, 4}) {
        ViewRequest v = base;
        v.quality.area_light_samples = a;
        row("area samples", std::to_string(a), v);
    }
    for (double s : {0.25, 0.5, 1.0}) {
        ViewRequest v = base;
        v.quality.resolution_scale = s;
        char b[16];
        std::snprintf(b, sizeof b, "%.2f", s);
        row("resolution scale", b, v);
    }
}

// Model only what the scene asks for: the same grotto with fewer light features; adds "lights" to out.
void lights_table(const Scene& scene, const ViewRequest& view, int reps, nlohmann::json& out) {
    std::printf(
        "\n## Lights cost only when the scene uses them (default knobs)\n\n| scene variant | CPU ms | rays | time / "
        "sun-only |\n|---|--:|--:|--:|\n");
    const auto variant = [&](const char* label, const std::function<void(Scene&)>& edit) {
        Scene copy = scene;
        edit(copy);
        return std::make_pair(label, time_render_vs_embree(copy, view, RendererOptions{"threads=1"}, reps));
    };
    const auto sun_only = variant("sun only, no shadows", [](Scene& s) {
        s.point_lights.clear();
        s.area_lights.clear();
        s.environment_lights.clear();
        for (auto& d : s.directional_lights) d.cast_shadows = false;
    });
    const std::vector<std::pair<const char*, RenderTimings>> rows{
        sun_only,
        variant("sun only, no shadows, + unused: zero-power point/area lights, glossy term of zero",
                [](Scene& s) {
                    s.point_lights.assign(1, PointLight{{0, 2, 0}, Rgb(0, 0, 0), true});
                    s.area_lights.assign(1, AreaLight{{0, 5, 0}, {1, 0, 0}, {0, 0, 1}, Rgb(0, 0, 0), true});
                    s.environment_lights.clear();
                    for (auto& d : s.directional_lights) d.cast_shadows = false;
                    for (auto& m : s.materials) m.specular = Rgb::Zero();
                }),
        variant("sun with shadows",
                [](Scene& s) {
                    s.point_lights.clear();
                    s.area_lights.clear();
                    s.environment_lights.clear();
                }),
        variant("+ 2 shadowing point lights",
                [](Scene& s) {
                    s.area_lights.clear();
                    s.environment_lights.clear();
                }),
        variant("+ area light (the full grotto, environment unoccluded)", [](Scene&) {}),
    };
    out["lights"] = nlohmann::json::array();
    for (const auto& [label, timing] : rows) {
        std::printf("| %s | %.1f | %llu | %.2f |\n", label, 1e3 * timing.render_s,
                    static_cast<unsigned long long>(timing.render_rays), timing.render_s / sun_only.second.render_s);
        out["lights"].push_back({{"variant", label},
                                 {"ms", 1e3 * timing.render_s},
                                 {"rays", timing.render_rays},
                                 {"time_vs_sun_only", timing.render_s / sun_only.second.render_s}});
    }
}

// Whether the scene file names meshes in the scans folder ("{scans}/..."): then it needs the scans.
bool scene_uses_scans(const std::filesystem::path& scene_file) {
    std::ifstream in(scene_file);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    return text.find("{scans}") != std::string::npos;
}

void write_json(const std::string& path, const nlohmann::json& out) {
    std::ofstream file(path);
    file << out.dump(1) << '\n';
    if (!file.flush()) throw std::runtime_error("cannot write " + path);
}

}  // namespace

int main(int argc, char** argv) {
    std::filesystem::path scene_file = std::filesystem::path(MOGAO_SOURCE_DIR) / "scenes" / "grotto.json";
    SceneLoadOptions options;
    int width = 320, height = 180, reps = 2;
    std::string json_file;
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string flag = argv[i];
        if (flag == "--scene") scene_file = argv[i + 1];
        else if (flag == "--scans") options.scans_dir = argv[i + 1];
        else if (flag == "--width") width = std::stoi(argv[i + 1]);
        else if (flag == "--height") height = std::stoi(argv[i + 1]);
        else if (flag == "--reps") reps = std::stoi(argv[i + 1]);
        else if (flag == "--json") json_file = argv[i + 1];
        else {
            std::fprintf(stderr, "unknown flag %s\n", flag.c_str());
            return 2;
        }
    }
    if (scene_uses_scans(scene_file) && !std::filesystem::exists(resolve_scans_dir(scene_file, options))) {
        std::printf("SKIP: real scans not found at %s\n", resolve_scans_dir(scene_file, options).c_str());
        return 77;
    }
    try {
        SceneLoadReport report;
        const Scene scene = load_scene(scene_file, options, &report);
        std::printf(
            "# grotto benchmark: %s, %zu instanced triangles, %dx%d cylinder frames, one thread, best of %d\n\n",
            scene_file.filename().c_str(), scene.triangle_count(), width, height, reps);
        nlohmann::json out = {{"bench", "grotto"},
                              {"scene", scene_file.filename().string()},
                              {"instanced_triangles", scene.triangle_count()},
                              {"width", width},
                              {"height", height},
                              {"reps", reps},
                              {"threads", 1},
                              {"walk_frame", 30}};

        ViewRequest view;
        view.size = {width, height};
        view.camera = CylinderScreen{3.0, 150.0, 0.2, 2.8, {0.0, 1.6, 0.0}};
        view.pose = make_camera_path("walk", scene.viewer, 60)[30];
        Renderer renderer(scene, RendererOptions{"threads=1"});

        // (a) raw Embree vs the full renderer, default quality.
        const RenderTimings t = time_frame(renderer, view, reps);
        std::printf("## Renderer vs raw Embree (same camera rays)\n\n| | CPU ms | rays | ratio |\n|---|--:|--:|--:|\n");
        std::printf("| (a) rtcIntersect16 camera packets | %.1f | %llu | 1.00 |\n", 1e3 * t.camera_rays_s,
                    static_cast<unsigned long long>(t.camera_rays));
        std::printf(
            "| (b) full renderer, default knobs (direct light, shadows from sun, 2 point, 1 area light) | %.1f | %llu "
            "| %.2f |\n\n",
            1e3 * t.render_s, static_cast<unsigned long long>(t.render_rays), t.ratio());
        out["renderer_vs_embree"] = {{"embree_camera_ms", 1e3 * t.camera_rays_s},
                                     {"embree_camera_rays", t.camera_rays},
                                     {"renderer_ms", 1e3 * t.render_s},
                                     {"renderer_rays", t.render_rays},
                                     {"ratio", t.ratio()}};

        knobs_table(renderer, scene, view, reps, out);
        lights_table(scene, view, reps, out);
        if (!json_file.empty()) write_json(json_file, out);
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "mogao_bench_grotto: %s\n", e.what());
        return 1;
    }
}
