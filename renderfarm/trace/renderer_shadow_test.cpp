// SPDX-License-Identifier: Apache-2.0
// Shadows: a sphere casts a dark disc on the floor under an overhead sun and nowhere else, and a
// flat plane lit at grazing incidence does not shadow itself (ray_offset.h at work).
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "renderfarm/trace/camera.h"
#include "renderfarm/trace/renderer.h"
#include "renderfarm/trace/test_scenes.h"

namespace mogao {
namespace {

TEST(RendererShadow, SphereShadowsTheFloorBelowItOnly) {
    Scene scene = test::make_sphere_over_floor();
    DirectionalLight sun;
    sun.direction_to_light = {0.0, 1.0, 0.0};
    sun.irradiance = Rgb(2.0f, 2.0f, 2.0f);
    scene.directional_lights = {sun};
    Renderer renderer(scene, RendererOptions{"threads=1", true});
    const ViewRequest request = test::look_at({0.0, 3.0, 3.0}, {0.0, 0.0, 0.0}, {96, 96}, 60.0);
    renderer.begin_frame(request);
    RgbFloatImage frame(renderer.render_size());
    renderer.render(PixelRect::whole(frame.size), frame);
    const CameraSetup camera = make_camera_setup(request, frame.size);

    const double lit = 0.5 / std::numbers::pi * 2.0;  // floor albedo 0.5, E = 2, cosθ = 1
    const Eigen::Vector3d centre(0.0, 1.0, 0.0);
    int shadowed = 0;
    int lit_pixels = 0;
    for (int y = 0; y < frame.size.height; ++y) {
        for (int x = 0; x < frame.size.width; ++x) {
            const Ray ray = generate_ray(camera, x + 0.5, y + 0.5);
            // Skip pixels whose ray passes near the sphere (radius 0.5): they see the sphere.
            const Eigen::Vector3d oc = centre - ray.origin;
            const double closest = (oc - oc.dot(ray.direction) * ray.direction).norm();
            if (closest < 0.52) continue;
            if (ray.direction.y() >= 0.0) continue;
            const Eigen::Vector3d q = ray.origin - ray.origin.y() / ray.direction.y() * ray.direction;
            if (std::abs(q.x()) > 1.95 || std::abs(q.z()) > 1.95) continue;  // off or at the floor edge
            const double r = std::hypot(q.x(), q.z());
            const float value = frame.at(x, y)[0];
            if (r < 0.47) {
                EXPECT_EQ(value, 0.0f) << "expected shadow at " << x << "," << y;
                ++shadowed;
            } else if (r > 0.53) {
                EXPECT_NEAR(value, lit, 1e-4 * lit) << "expected light at " << x << "," << y;
                ++lit_pixels;
            }
        }
    }
    EXPECT_GT(shadowed, 50);
    EXPECT_GT(lit_pixels, 1000);
}

// Sun 89.9° from the plane normal: shadow rays leave almost parallel to the surface, from hit
// points with rounding error. Every pixel of the plane must still be lit with E cos(89.9°).
TEST(RendererShadow, GrazingSunDoesNotSelfShadowAFlatPlane) {
    Scene scene;
    scene.source = "grazing_plane";
    scene.meshes.push_back(test::make_grid(64, 3.0f, false));
    Material m;
    m.albedo = Rgb(0.8f, 0.8f, 0.8f);
    scene.materials = {m};
    // Tilt and move the plane so that vertex coordinates are not round numbers.
    Eigen::Affine3d xf = Eigen::Affine3d::Identity();
    xf.translate(Eigen::Vector3d(0.37, 1.13, -0.71));
    xf.rotate(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1.0, 0.2, 0.3).normalized()));
    scene.instances = {Instance{"plane", 0, 0, xf}};
    const Eigen::Vector3d normal = xf.linear() * Eigen::Vector3d::UnitY();
    const Eigen::Vector3d tangent = (xf.linear() * Eigen::Vector3d(1.0, 0.0, 0.3)).normalized();
    const double grazing = 89.9 * std::numbers::pi / 180.0;
    DirectionalLight sun;
    sun.direction_to_light = std::cos(grazing) * normal + std::sin(grazing) * tangent;
    sun.irradiance = Rgb(100.0f, 100.0f, 100.0f);
    scene.directional_lights = {sun};

    Renderer renderer(scene, RendererOptions{"threads=1", true});
    const Eigen::Vector3d target = xf.translation();
    const ViewRequest request =
        test::look_at(target + 2.5 * normal + Eigen::Vector3d(0.3, 0.0, 0.2), target, {80, 80}, 60.0);
    renderer.begin_frame(request);
    RgbFloatImage frame(renderer.render_size());
    renderer.render(PixelRect::whole(frame.size), frame);

    const float expected = static_cast<float>(0.8 / std::numbers::pi * 100.0 * std::cos(grazing));
    int dark = 0;
    for (int y = 0; y < frame.size.height; ++y) {
        for (int x = 0; x < frame.size.width; ++x) {
            const float value = frame.at(x, y)[1];
            if (std::abs(value - expected) > 1e-3f * expected) ++dark;
        }
    }
    EXPECT_EQ(dark, 0) << "pixels not lit with " << expected;
}

}  // namespace
}  // namespace mogao
