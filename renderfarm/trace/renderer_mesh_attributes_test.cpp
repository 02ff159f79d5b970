// SPDX-License-Identifier: Apache-2.0
// Meshes loaded from files through the renderer: a scan-like mesh written 1e6 m from its file's
// origin renders like the same mesh at the origin (PLY and OBJ), and vertex colours tint the
// albedo exactly.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include <gtest/gtest.h>
#include <unistd.h>

#include "renderfarm/scene/mesh_io.h"
#include "renderfarm/scene/procedural.h"
#include "renderfarm/trace/renderer.h"
#include "renderfarm/trace/test_scenes.h"

namespace mogao {
namespace {

namespace fs = std::filesystem;

// A bumpy sphere (radius 0.3 m, 2 mm bumps) as text, every vertex moved by `offset`.
std::string write_bumpy_sphere(const fs::path& path, const Eigen::Vector3d& offset) {
    const Mesh sphere = make_uv_sphere(0.3, 96, 48);
    const bool ply = path.extension() == ".ply";
    std::string out;
    if (ply) {
        out = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(sphere.positions.size()) +
              "\nproperty double x\nproperty double y\nproperty double z\nelement face " +
              std::to_string(sphere.triangles.size()) + "\nproperty list uchar int vertex_indices\nend_header\n";
    }
    char line[160];
    for (std::size_t i = 0; i < sphere.positions.size(); ++i) {
        const Eigen::Vector3d p = sphere.positions[i].cast<double>();
        const double bump = 1.0 + 0.007 * std::sin(40.0 * p.x()) * std::sin(40.0 * p.y());
        const Eigen::Vector3d q = p * bump + offset;
        std::snprintf(line, sizeof line, "%s%.10f %.10f %.10f\n", ply ? "" : "v ", q.x(), q.y(), q.z());
        out += line;
    }
    for (const auto& t : sphere.triangles) {
        std::snprintf(line, sizeof line, ply ? "3 %u %u %u\n" : "f %u %u %u\n", t[0] + (ply ? 0 : 1),
                      t[1] + (ply ? 0 : 1), t[2] + (ply ? 0 : 1));
        out += line;
    }
    std::ofstream(path, std::ios::binary) << out;
    return path.string();
}

// Loads like the scene reader does (load_mesh, normals, recentre into the transform) and renders
// from 1 m in front of the sphere's centre.
RgbFloatImage render_file(const fs::path& path, const Eigen::Vector3d& offset) {
    Scene scene;
    scene.source = path.string();
    Mesh mesh = load_mesh(path);
    compute_vertex_normals(mesh);
    const Eigen::Vector3d centre = recentre_mesh(mesh);
    scene.meshes.push_back(std::move(mesh));
    scene.materials = {Material{}};
    Instance inst{"scan", 0, 0, Eigen::Affine3d::Identity()};
    inst.object_to_world.translate(centre);
    scene.instances = {inst};
    DirectionalLight sun;
    sun.direction_to_light = Eigen::Vector3d(0.5, 0.7, 0.6).normalized();
    sun.cast_shadows = true;
    scene.directional_lights = {sun};
    Renderer renderer(scene, RendererOptions{"threads=1", true});
    renderer.begin_frame(test::look_at(offset + Eigen::Vector3d(0.0, 0.0, 1.0), offset, {64, 64}, 45.0));
    RgbFloatImage frame(renderer.render_size());
    renderer.render(PixelRect::whole(frame.size), frame);
    return frame;
}

TEST(RendererMeshFile, FileFarFromOriginRendersLikeAtOrigin) {
    const fs::path dir = fs::temp_directory_path() / ("mogao-far-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const Eigen::Vector3d far(1.0e6, 2.0e5, -1.0e6);
    for (const std::string ext : {".ply", ".obj"}) {
        const fs::path near_file = dir / ("near" + ext);
        const fs::path far_file = dir / ("far" + ext);
        write_bumpy_sphere(near_file, Eigen::Vector3d::Zero());
        write_bumpy_sphere(far_file, far);
        const RgbFloatImage a = render_file(near_file, Eigen::Vector3d::Zero());
        const RgbFloatImage b = render_file(far_file, far);
        double diff = 0.0;
        double sum = 0.0;
        for (std::size_t i = 0; i < a.pixels.size(); ++i) {
            diff += std::abs(a.pixels[i] - b.pixels[i]);
            sum += a.pixels[i];
        }
        std::printf("%s at 1e6 m: mean |diff| / mean = %.2e\n", ext.c_str(), diff / sum);
        EXPECT_GT(sum, 0.0);
        EXPECT_LT(diff / sum, 1e-3) << ext;  // float steps at 1e6 m are 6 cm: a 30 cm sphere falls apart
    }
    fs::remove_all(dir);
}

TEST(RendererMeshFile, VertexColoursTintTheAlbedo) {
    Scene scene;
    scene.source = "coloured";
    Mesh grid = test::make_grid(1, 2.0f, false);
    for (std::size_t i = 0; i < grid.positions.size(); ++i) grid.colors.emplace_back(0.8f, 0.4f, 0.1f);
    scene.meshes.push_back(grid);
    Material m;
    m.albedo = Rgb(0.5f, 0.5f, 1.0f);
    scene.materials = {m};
    scene.instances = {Instance{"floor", 0, 0, Eigen::Affine3d::Identity()}};
    DirectionalLight sun;
    sun.direction_to_light = {0.0, 1.0, 0.0};
    sun.irradiance = Rgb::Constant(std::numbers::pi_v<float>);
    scene.directional_lights = {sun};
    Renderer renderer(scene, RendererOptions{"threads=1", true});
    renderer.begin_frame(test::look_at({0.0, 3.0, 0.01}, {0.0, 0.0, 0.0}, {16, 16}, 30.0));
    RgbFloatImage frame(renderer.render_size());
    renderer.render(PixelRect::whole(frame.size), frame);
    const float* centre = frame.at(8, 8);
    EXPECT_NEAR(centre[0], 0.5f * 0.8f, 1e-5f);
    EXPECT_NEAR(centre[1], 0.5f * 0.4f, 1e-5f);
    EXPECT_NEAR(centre[2], 1.0f * 0.1f, 1e-5f);
}

}  // namespace
}  // namespace mogao
