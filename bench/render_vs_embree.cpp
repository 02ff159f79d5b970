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
// Usage: mogao_bench_render [--width W] [--height H] [--spp N] [--reps N] [--grid N] [--json FILE]
// The table goes to stdout; --json FILE also writes every figure as JSON (for bench/regenerate-docs).
// Timings use Renderer/RenderTimings from renderfarm/trace/render_timing.h, which the farm can
// reuse on a real scene: time_render_vs_embree(scene, request).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "renderfarm/scene/procedural.h"
#include "renderfarm/scene/scene.h"
#include "renderfarm/trace/render_timing.h"
#include "renderfarm/trace/renderer.h"

namespace {

using namespace mogao;

// Height field y = h(x, z) over [-10, 10]² with n x n cells (2 n² triangles), analytic normals.
Mesh height_field(int n) {
    Mesh mesh;
    mesh.source = "height_field";
    const auto height = [](double x, double z) { return 0.4 * std::sin(1.3 * x) * std::cos(0.9 * z) + 0.1 * std::sin(4.0 * x + 3.0 * z); };
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
        std::printf("    (c2)/(c1) = %.3f  (unused features should cost nothing: ~1.0)\n", unused.render_s / plain.render_s);
        std::printf("    (c3)/(c1) = %.3f  (what shadows and an area light cost when used)\n", used.render_s / plain.render_s);
        std::printf("    (c4)/(c1) = %.3f  (a scene without colour or texture pays nothing: ~1.0)\n",
                    colour_unused.render_s / plain.render_s);
        std::printf("    (c5)/(c1) = %.3f  (what vertex colours and a bilinear texture cost when used)\n",
                    colour_used.render_s / plain.render_s);
        std::printf("    BVH build (c1): %.2f s\n", plain.build_s);
        if (!json_file.empty()) {
            const nlohmann::json out = {
                {"bench", "render_vs_embree"},
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
                {"ratio_c5_over_c1", colour_used.render_s / plain.render_s}};
            std::ofstream file(json_file);
            file << out.dump(1) << '\n';
            if (!file.flush()) throw std::runtime_error("cannot write " + json_file);
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "mogao_bench_render: %s\n", e.what());
        return 1;
    }
    return 0;
}
