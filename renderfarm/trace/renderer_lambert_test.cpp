// SPDX-License-Identifier: Apache-2.0
// Analytic check of the direct-light path: a finely tessellated unit sphere under one sun must
// show L = albedo/π · E · max(0, n·l) with n the exact sphere normal where each camera ray hits.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "renderfarm/scene/procedural.h"
#include "renderfarm/trace/camera.h"
#include "renderfarm/trace/renderer.h"
#include "renderfarm/trace/test_scenes.h"

namespace mogao {
namespace {

// Nearest intersection of a ray with the unit sphere at the origin, if any.
bool hit_unit_sphere(const Ray& ray, Eigen::Vector3d& point) {
    const double b = ray.origin.dot(ray.direction);
    const double c = ray.origin.squaredNorm() - 1.0;
    const double disc = b * b - c;
    if (disc < 0.0) return false;
    point = ray.origin + (-b - std::sqrt(disc)) * ray.direction;
    return true;
}

TEST(RendererLambert, TessellatedSphereMatchesAnalyticRadiance) {
    Scene scene;
    scene.source = "lambert_sphere";
    scene.meshes.push_back(make_uv_sphere(1.0, 200, 100));
    Material m;
    m.albedo = Rgb(0.5f, 0.5f, 0.5f);
    scene.materials = {m};
    scene.instances = {Instance{"sphere", 0, 0, Eigen::Affine3d::Identity()}};
    DirectionalLight sun;
    sun.direction_to_light = Eigen::Vector3d(0.3, 0.8, 0.5).normalized();
    sun.irradiance = Rgb(3.0f, 2.0f, 1.0f);
    sun.cast_shadows = true;
    scene.directional_lights = {sun};

    // Each pixel is compared with the exact sphere along its centre ray: sample pixel centres.
    RendererOptions centres{"threads=1", true};
    centres.jitter_one_spp = false;
    Renderer renderer(scene, centres);
    ViewRequest request = test::look_at({0.5, 0.3, 4.0}, {0.0, 0.0, 0.0}, {96, 80}, 35.0);
    renderer.begin_frame(request);
    RgbFloatImage frame(renderer.render_size());
    renderer.render(PixelRect::whole(frame.size), frame);
    const CameraSetup camera = make_camera_setup(request, frame.size);

    // Tolerance: 2% relative + 1% of the full-on radiance (E albedo/π) absolute, for the
    // tessellation (interpolated vs exact normal, inscribed hit point). Within one facet angle
    // (1.8°, cos_l < sin 2° = 0.035) of the terminator the absolute part is 3.5%: there the
    // renderer drops light below the facet's geometric normal (ng·l <= 0), which the exact
    // sphere does not have.
    double worst = 0.0;  // largest |error| / full radiance away from / near the terminator, reported
    double worst_terminator = 0.0;
    int checked = 0;
    int background = 0;
    for (int y = 0; y < frame.size.height; ++y) {
        for (int x = 0; x < frame.size.width; ++x) {
            const Ray ray = generate_ray(camera, x + 0.5, y + 0.5);
            const float* got = frame.at(x, y);
            Eigen::Vector3d p;
            if (!hit_unit_sphere(ray, p)) {
                // Misses the exact sphere, so misses the inscribed tessellation: no environment.
                EXPECT_EQ(got[0], 0.0f) << x << "," << y;
                ++background;
                continue;
            }
            const double distance_to_axis = (ray.origin + ray.direction * -ray.origin.dot(ray.direction)).norm();
            if (distance_to_axis > 0.998) continue;  // silhouette: may miss the inscribed polyhedron
            const double cos_l = std::max(0.0, p.normalized().dot(sun.direction_to_light));
            for (int c = 0; c < 3; ++c) {
                const double full = 0.5 / std::numbers::pi * sun.irradiance[c];
                const double expected = full * cos_l;
                const double absolute = cos_l < 0.035 ? 0.035 : 0.01;
                EXPECT_NEAR(got[c], expected, 0.02 * expected + absolute * full)
                    << "pixel " << x << "," << y << " c" << c;
                (cos_l < 0.035 ? worst_terminator : worst) =
                    std::max(cos_l < 0.035 ? worst_terminator : worst, std::abs(got[c] - expected) / full);
            }
            ++checked;
        }
    }
    RecordProperty("worst_error_of_full", std::to_string(worst));
    std::printf("Lambert sphere: %d pixels checked, worst |error| = %.4f (terminator band %.4f) of E albedo/pi\n",
                checked, worst, worst_terminator);
    EXPECT_GT(checked, 2000);
    EXPECT_GT(background, 1000);
}

}  // namespace
}  // namespace mogao
