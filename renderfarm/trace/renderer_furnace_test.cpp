// SPDX-License-Identifier: Apache-2.0
// White furnace tests (PBRT 4th ed. §13.1.1 / Pharr et al.'s "white furnace" check): an object of
// albedo-1 material under a uniform environment of radiance L must look exactly like the sky,
// L in every pixel, at 0, 1 and many bounces; an energy-conserving glossy material may only look
// darker, never brighter. And the environment is an occluded light: inside a closed room it
// delivers nothing, whatever ao_samples and bounces say.
#include <algorithm>
#include <cstdio>

#include <gtest/gtest.h>

#include "renderfarm/scene/procedural.h"
#include "renderfarm/trace/renderer.h"
#include "renderfarm/trace/test_scenes.h"

namespace mogao {
namespace {

constexpr float kSky = 0.7f;

RgbFloatImage render(const Scene& scene, const ViewRequest& request) {
    Renderer renderer(scene, RendererOptions{"threads=1", true});
    renderer.begin_frame(request);
    RgbFloatImage frame(renderer.render_size());
    renderer.render(PixelRect::whole(frame.size), frame);
    return frame;
}

Scene sphere_in_furnace(const Material& m) {
    Scene scene;
    scene.source = "furnace";
    scene.meshes.push_back(make_uv_sphere(1.0, 160, 80));
    scene.materials = {m};
    scene.instances = {Instance{"sphere", 0, 0, Eigen::Affine3d::Identity()}};
    scene.environment_lights = {EnvironmentLight{Rgb::Constant(kSky)}};
    return scene;
}

ViewRequest furnace_view(int spp, int ao, int bounces) {
    ViewRequest request = test::look_at({0.0, 0.4, 3.5}, {0.0, 0.0, 0.0}, {48, 48}, 40.0);
    request.quality.spp = spp;
    request.quality.ao_samples = ao;
    request.quality.max_bounces = bounces;
    return request;
}

// Lambert albedo 1 on a convex object: every environment sample escapes and carries π f L = L,
// so each pixel is L up to the tessellation (rays between the shading and geometric planes are
// dropped: < 0.1%).
TEST(RendererFurnace, WhiteLambertSphereIsInvisibleAtAnyBounceCount) {
    Material white;
    white.albedo = Rgb::Ones();
    const Scene scene = sphere_in_furnace(white);
    for (const int bounces : {0, 1, 16}) {
        const RgbFloatImage frame = render(scene, furnace_view(2, 0, bounces));
        for (std::size_t i = 0; i < frame.pixels.size(); ++i) {
            ASSERT_NEAR(frame.pixels[i], kSky, 2e-3f * kSky) << "bounces " << bounces << " value " << i;
        }
    }
}

// A concave arrangement (sphere over a floor, both albedo 1): light reaches the floor under the
// sphere only by interreflection, so only with many bounces is every pixel L. Per pixel the
// estimate is noisy; the image mean must be L within 2% and no pixel may exceed it by much.
TEST(RendererFurnace, WhiteSphereOverFloorConvergesToSkyWithBounces) {
    Scene scene = test::make_sphere_over_floor();
    for (Material& m : scene.materials) {
        m.albedo = Rgb::Ones();
        m.specular = Rgb::Zero();
    }
    scene.environment_lights = {EnvironmentLight{Rgb::Constant(kSky)}};
    ViewRequest request = test::look_at({0.0, 2.2, 2.2}, {0.0, 0.4, 0.0}, {40, 40}, 70.0);
    request.quality.spp = 16;
    request.quality.ao_samples = 2;
    request.quality.max_bounces = 32;
    const RgbFloatImage frame = render(scene, request);
    double sum = 0.0;
    float worst = 0.0f;
    for (const float v : frame.pixels) {
        sum += v;
        worst = std::max(worst, v);
    }
    const double mean = sum / static_cast<double>(frame.pixels.size());
    std::printf("sphere over floor, 32 bounces: mean %.4f (sky %.4f), max %.4f\n", mean, kSky, worst);
    EXPECT_NEAR(mean, kSky, 0.02 * kSky);
    EXPECT_LT(worst, 1.5f * kSky);
}

// Glossy materials under the furnace: never brighter than the sky (energy conservation), and
// the glossy lobe does see the environment (a purely glossy sphere is not black).
TEST(RendererFurnace, GlossySpheresReflectNoMoreThanTheSky) {
    struct Case {
        float albedo, specular, shininess;
    };
    for (const Case c : {Case{1.0f, 0.25f, 40.0f}, Case{0.0f, 1.0f, 2.0f}, Case{0.0f, 1.0f, 40.0f}}) {
        Material m;
        m.albedo = Rgb::Constant(c.albedo);
        m.specular = Rgb::Constant(c.specular);
        m.shininess = c.shininess;
        const Scene scene = sphere_in_furnace(m);
        for (const int bounces : {0, 4}) {
            const RgbFloatImage frame = render(scene, furnace_view(16, 16, bounces));
            double sum = 0.0;
            for (const float v : frame.pixels) sum += v;
            const double mean = sum / static_cast<double>(frame.pixels.size());
            std::printf("albedo %.2f specular %.2f s %.0f bounces %d: mean %.4f of sky %.4f\n", c.albedo, c.specular,
                        c.shininess, bounces, mean, kSky);
            EXPECT_LE(mean, kSky * 1.01) << c.specular << " " << c.shininess;
            EXPECT_GE(mean, kSky * 0.75) << c.specular << " " << c.shininess;
        }
    }
}

// A closed box seen from inside, lit only by the environment: no sky light can arrive, with or
// without ambient-occlusion samples and bounces.
TEST(RendererFurnace, ClosedRoomReceivesNoEnvironmentLight) {
    Scene scene;
    scene.source = "closed_room";
    scene.meshes.push_back(make_box(4.0, 3.0, 5.0));
    Material m;
    m.albedo = Rgb::Constant(0.8f);
    scene.materials = {m};
    scene.instances = {Instance{"room", 0, 0, Eigen::Affine3d::Identity()}};
    scene.environment_lights = {EnvironmentLight{Rgb::Constant(1.0f)}};
    for (const int ao : {0, 4}) {
        for (const int bounces : {0, 3}) {
            ViewRequest request = test::look_at({0.0, 0.2, 1.0}, {0.5, 0.0, -2.0}, {32, 32}, 90.0);
            request.quality.spp = 2;
            request.quality.ao_samples = ao;
            request.quality.max_bounces = bounces;
            const RgbFloatImage frame = render(scene, request);
            const float brightest = *std::max_element(frame.pixels.begin(), frame.pixels.end());
            EXPECT_EQ(brightest, 0.0f) << "ao_samples " << ao << " bounces " << bounces;
        }
    }
}

}  // namespace
}  // namespace mogao
