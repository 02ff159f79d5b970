// SPDX-License-Identifier: Apache-2.0
// Each light type and the glossy lobe against closed-form values on a flat floor, plus the
// no-double-counting rule for escaping bounce rays.
#include <cmath>
#include <functional>
#include <numbers>

#include <gtest/gtest.h>

#include "renderfarm/trace/camera.h"
#include "renderfarm/trace/renderer.h"
#include "renderfarm/trace/test_scenes.h"

namespace mogao {
namespace {

constexpr double kPi = std::numbers::pi;

Scene floor_scene(const Material& material) {
    Scene scene;
    scene.source = "floor";
    scene.meshes.push_back(test::make_grid(16, 4.0f, true));
    scene.materials = {material};
    scene.instances = {Instance{"floor", 0, 0, Eigen::Affine3d::Identity()}};
    return scene;
}

Material matte(float albedo) {
    Material m;
    m.albedo = Rgb(albedo, albedo, albedo);
    return m;
}

ViewRequest floor_view() { return test::look_at({0.4, 3.0, 2.5}, {0.0, 0.0, -0.3}, {48, 40}, 50.0); }

// These checks compare each pixel with the analytic radiance along its centre ray, so the 1-spp
// frames are sampled at pixel centres (the renderer's default places the sample at a Sobol' point).
RgbFloatImage render(const Scene& scene, const ViewRequest& request) {
    RendererOptions centres{"threads=1", true};
    centres.jitter_one_spp = false;
    Renderer renderer(scene, centres);
    renderer.begin_frame(request);
    RgbFloatImage frame(renderer.render_size());
    renderer.render(PixelRect::whole(frame.size), frame);
    return frame;
}

// Calls check(x, y, floor point, camera ray, value) for every pixel whose centre ray hits the
// floor square (|x|, |z| < 3.9 m); returns how many.
int for_floor_pixels(const RgbFloatImage& frame, const ViewRequest& request,
                     const std::function<void(int, int, const Eigen::Vector3d&, const Ray&, const float*)>& check) {
    const CameraSetup camera = make_camera_setup(request, frame.size);
    int count = 0;
    for (int y = 0; y < frame.size.height; ++y) {
        for (int x = 0; x < frame.size.width; ++x) {
            const Ray ray = generate_ray(camera, x + 0.5, y + 0.5);
            if (ray.direction.y() >= 0.0) continue;
            const Eigen::Vector3d q = ray.origin - ray.origin.y() / ray.direction.y() * ray.direction;
            if (std::abs(q.x()) > 3.9 || std::abs(q.z()) > 3.9) continue;
            check(x, y, q, ray, frame.at(x, y));
            ++count;
        }
    }
    return count;
}

TEST(RendererLights, PointLightFollowsInverseSquareLaw) {
    Scene scene = floor_scene(matte(0.5f));
    scene.point_lights = {PointLight{{0.3, 2.0, -0.2}, Rgb(8.0f, 4.0f, 2.0f), true}};
    const ViewRequest request = floor_view();
    const RgbFloatImage frame = render(scene, request);
    const int n =
        for_floor_pixels(frame, request, [&](int x, int y, const Eigen::Vector3d& q, const Ray&, const float* v) {
            const Eigen::Vector3d to_light = scene.point_lights[0].position - q;
            const double d2 = to_light.squaredNorm();
            const double cos = to_light.y() / std::sqrt(d2);
            for (int c = 0; c < 3; ++c) {
                const double expected = 0.5 / kPi * scene.point_lights[0].intensity[c] * cos / d2;
                EXPECT_NEAR(v[c], expected, 1e-4 * expected + 1e-7) << x << "," << y;
            }
        });
    EXPECT_GT(n, 1000);
}

TEST(RendererLights, SmallAreaLightMatchesSolidAngleFormulaAndIsOneSided) {
    Scene scene = floor_scene(matte(0.5f));
    // 0.1 x 0.1 m at 2 m, emitting downward (edge_u x edge_v = x x z = -y). Using the light's
    // own cosθ_l = direction.y (its normal is -y) and the floor's cosθ = direction.y as well.
    const Eigen::Vector3d centre(0.0, 2.0, -0.3);
    scene.area_lights = {AreaLight{centre - Eigen::Vector3d(0.05, 0.0, 0.05),
                                   {0.1, 0.0, 0.0},
                                   {0.0, 0.0, 0.1},
                                   Rgb(200.0f, 200.0f, 200.0f),
                                   true}};
    ViewRequest request = floor_view();
    request.quality.area_light_samples = 256;
    const RgbFloatImage frame = render(scene, request);
    // Reference: E(q) = ∫ L cosθ cosθ_l / d² dA by a 32x32 midpoint rule over the light. Each pixel
    // within 1% (Monte Carlo noise of 256 samples), the mean relative error within 0.2% (bias).
    const AreaLight& light = scene.area_lights[0];
    double error_sum = 0.0;
    const int n =
        for_floor_pixels(frame, request, [&](int x, int y, const Eigen::Vector3d& q, const Ray&, const float* v) {
            double irradiance = 0.0;
            for (int i = 0; i < 32; ++i) {
                for (int j = 0; j < 32; ++j) {
                    const Eigen::Vector3d p =
                        light.corner + (i + 0.5) / 32.0 * light.edge_u + (j + 0.5) / 32.0 * light.edge_v;
                    const Eigen::Vector3d w = p - q;
                    const double d2 = w.squaredNorm();
                    irradiance += 200.0 * (w.y() / std::sqrt(d2)) * (w.y() / std::sqrt(d2)) / d2 * (0.01 / 1024.0);
                }
            }
            const double expected = 0.5 / kPi * irradiance;
            EXPECT_NEAR(v[0], expected, 0.01 * expected) << x << "," << y;
            error_sum += (v[0] - expected) / expected;
        });
    EXPECT_GT(n, 1000);
    EXPECT_NEAR(error_sum / n, 0.0, 0.002);

    // Flipped to emit upward: the floor receives nothing.
    std::swap(scene.area_lights[0].edge_u, scene.area_lights[0].edge_v);
    const RgbFloatImage dark = render(scene, request);
    for_floor_pixels(dark, request, [](int x, int y, const Eigen::Vector3d&, const Ray&, const float* v) {
        EXPECT_EQ(v[0], 0.0f) << x << "," << y;
    });
}

TEST(RendererLights, EnvironmentIsAlbedoTimesRadianceOnAnOpenFloorAndBouncesDoNotAddIt) {
    Scene scene = floor_scene(matte(0.6f));
    scene.environment_lights = {EnvironmentLight{Rgb(0.2f, 0.3f, 0.4f)}, EnvironmentLight{Rgb(0.1f, 0.1f, 0.1f)}};
    const ViewRequest base = floor_view();
    ViewRequest ao = base;
    ao.quality.ao_samples = 8;
    ViewRequest bounces = ao;
    bounces.quality.max_bounces = 3;
    const RgbFloatImage plain = render(scene, base);
    const RgbFloatImage with_ao = render(scene, ao);
    const RgbFloatImage with_bounces = render(scene, bounces);
    const float sky[3] = {0.3f, 0.4f, 0.5f};
    int floor_pixels = 0;
    const CameraSetup camera = make_camera_setup(base, plain.size);
    for (int y = 0; y < plain.size.height; ++y) {
        for (int x = 0; x < plain.size.width; ++x) {
            const Ray ray = generate_ray(camera, x + 0.5, y + 0.5);
            for (int c = 0; c < 3; ++c) {
                // Nothing occludes an open floor, and escaping bounce rays add nothing: all equal.
                EXPECT_FLOAT_EQ(with_ao.at(x, y)[c], plain.at(x, y)[c]) << x << "," << y;
                EXPECT_FLOAT_EQ(with_bounces.at(x, y)[c], plain.at(x, y)[c]) << x << "," << y;
            }
            if (ray.direction.y() >= 0.0) continue;
            const Eigen::Vector3d q = ray.origin - ray.origin.y() / ray.direction.y() * ray.direction;
            if (std::abs(q.x()) > 3.9 || std::abs(q.z()) > 3.9) continue;
            ++floor_pixels;
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(plain.at(x, y)[c], 0.6f * sky[c], 1e-6f);
        }
    }
    EXPECT_GT(floor_pixels, 1000);
    EXPECT_FLOAT_EQ(plain.at(0, 0)[2], sky[2]);  // top-left pixel looks at the sky
}

// The glossy lobe of shading.h, written out in double: GGX D, height-correlated Smith G2, the
// (1 - k_s) diffuse mix and α = sqrt(2 / (s + 2)).
double ggx_reference(const Eigen::Vector3d& wo, const Eigen::Vector3d& wi, double albedo, double ks, double s) {
    const double alpha2 = 2.0 / (s + 2.0);
    const Eigen::Vector3d h = (wo + wi).normalized();
    const double d = alpha2 / (kPi * std::pow(h.y() * h.y() * (alpha2 - 1.0) + 1.0, 2.0));
    const auto lambda = [&](double c) { return 0.5 * (std::sqrt(1.0 + alpha2 * (1.0 - c * c) / (c * c)) - 1.0); };
    const double g2 = 1.0 / (1.0 + lambda(wo.y()) + lambda(wi.y()));
    return (1.0 - ks) * albedo / kPi + ks * d * g2 / (4.0 * wo.y() * wi.y());
}

TEST(RendererLights, GlossyLobeMatchesGgx) {
    Material shiny = matte(0.4f);
    shiny.specular = Rgb(0.5f, 0.5f, 0.5f);
    shiny.shininess = 20.0f;
    Scene scene = floor_scene(shiny);
    DirectionalLight sun;
    sun.direction_to_light = Eigen::Vector3d(-0.2, 1.0, -0.9).normalized();
    sun.irradiance = Rgb(2.0f, 2.0f, 2.0f);
    scene.directional_lights = {sun};
    const ViewRequest request = floor_view();
    const RgbFloatImage frame = render(scene, request);
    double brightest = 0.0;
    const int n =
        for_floor_pixels(frame, request, [&](int x, int y, const Eigen::Vector3d&, const Ray& ray, const float* v) {
            const Eigen::Vector3d l = sun.direction_to_light;
            const double f = ggx_reference(-ray.direction, l, 0.4, 0.5, 20.0);
            const double expected = f * 2.0 * l.y();
            EXPECT_NEAR(v[0], expected, 2e-4 * expected) << x << "," << y;
            brightest = std::max(brightest, static_cast<double>(v[0]));
        });
    EXPECT_GT(n, 1000);
    EXPECT_GT(brightest, 2.0 * 0.2 / kPi * 2.0 * sun.direction_to_light.y());  // a highlight is in view
}

}  // namespace
}  // namespace mogao
