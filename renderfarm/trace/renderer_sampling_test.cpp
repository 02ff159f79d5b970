// SPDX-License-Identifier: Apache-2.0
// Cheaper and better samples must not change what the renderer converges to:
//  * Russian roulette (RendererOptions::russian_roulette, integrator.h) is unbiased: the frame mean
//    over many seeds agrees with the one without roulette within a tolerance derived from the
//    measured variance of both, and it traces fewer rays;
//  * the one sample of a 1-spp frame sits at a scrambled Sobol' point of the pixel
//    (RendererOptions::jitter_one_spp): deterministic per (seed, frame_id), and 1-spp passes
//    accumulated over frame ids converge to the pixel's covered fraction at a sharp edge, which
//    pixel-centre sampling never does;
//  * the environment taken from escaping bounce rays (RendererOptions::environment_from_bounce,
//    integrator.h) is unbiased against its own ray at every vertex and traces fewer rays.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "renderfarm/trace/renderer.h"
#include "renderfarm/trace/test_scenes.h"

namespace mogao {
namespace {

RendererOptions options(bool roulette, bool jitter_one_spp = true) {
    RendererOptions o{"threads=1", true};
    o.russian_roulette = roulette;
    o.jitter_one_spp = jitter_one_spp;
    return o;
}

// A glossy sphere in a closed 4 x 4 x 4 m room of grey (albedo 0.5) walls lit by two point
// lights: no path escapes, so without roulette every path runs to max_bounces while its
// throughput falls by about half per bounce, what roulette is for.
Scene roulette_scene() {
    Scene scene = test::make_sphere_over_floor();
    const auto wall = [&](const Eigen::Vector3d& at, const Eigen::Vector3d& axis) {
        Instance w{"wall", 1, 0, Eigen::Affine3d::Identity()};  // the floor's 4 x 4 grid (meshes are two-sided)
        w.object_to_world.translate(at);
        w.object_to_world.rotate(Eigen::AngleAxisd(std::numbers::pi / 2.0, axis));
        scene.instances.push_back(w);
    };
    Instance ceiling{"ceiling", 1, 0, Eigen::Affine3d::Identity()};
    ceiling.object_to_world.translate(Eigen::Vector3d(0.0, 4.0, 0.0));
    scene.instances.push_back(ceiling);
    wall({0.0, 2.0, -2.0}, Eigen::Vector3d::UnitX());
    wall({0.0, 2.0, 2.0}, Eigen::Vector3d::UnitX());
    wall({-2.0, 2.0, 0.0}, Eigen::Vector3d::UnitZ());
    wall({2.0, 2.0, 0.0}, Eigen::Vector3d::UnitZ());
    scene.point_lights = {PointLight{{1.0, 2.0, 1.0}, Rgb(2.0f, 1.5f, 1.0f), true},
                          PointLight{{-1.2, 3.5, -1.0}, Rgb(1.0f, 1.0f, 1.5f), true}};
    return scene;
}

ViewRequest roulette_view(std::uint64_t seed, int bounces) {
    ViewRequest request = test::look_at({0.3, 2.0, 1.8}, {0.0, 0.8, 0.0}, {24, 16}, 70.0);
    request.quality.spp = 8;
    request.quality.max_bounces = bounces;
    request.seed = seed;
    return request;
}

double frame_mean(const RgbFloatImage& f) {
    double sum = 0.0;
    for (const float v : f.pixels) sum += v;
    return sum / static_cast<double>(f.pixels.size());
}

struct SeedMean {
    double mean = 0.0;
    double error = 0.0;  // standard error of the mean over seeds
    double rays = 0.0;   // per frame
};

SeedMean over_seeds(bool roulette, int bounces, int seeds) {
    const Scene scene = roulette_scene();
    Renderer renderer(scene, options(roulette));
    std::vector<double> means;
    SeedMean out;
    for (int s = 0; s < seeds; ++s) {
        renderer.begin_frame(roulette_view(500u + static_cast<std::uint64_t>(s), bounces));
        RgbFloatImage frame(renderer.render_size());
        out.rays += static_cast<double>(renderer.render(PixelRect::whole(frame.size), frame).rays) / seeds;
        means.push_back(frame_mean(frame));
    }
    for (const double m : means) out.mean += m;
    out.mean /= static_cast<double>(seeds);
    double var = 0.0;
    for (const double m : means) var += (m - out.mean) * (m - out.mean);
    out.error = std::sqrt(var / static_cast<double>(seeds - 1) / static_cast<double>(seeds));
    return out;
}

// Tolerance: the two means are averages of independent per-seed frame means, so their difference
// has standard deviation sqrt(e_on² + e_off²) (measured from the seeds); an unbiased estimator
// stays within 4.5 of those with probability > 0.9999. The tolerance itself must be under 1 % of
// the mean, so a bias of a per cent or more (a forgotten 1/q, a roulette on the first bounce's
// throughput before the BRDF) cannot hide in it. Roulette must also save rays: at 6 bounces in
// this room under 0.6 of the rays per frame without it (measured 0.36).
TEST(RendererRoulette, FrameMeanMatchesNoRouletteAndFewerRaysAreTraced) {
    const int bounces = 6;
    const SeedMean off = over_seeds(false, bounces, 40);
    const SeedMean on = over_seeds(true, bounces, 80);  // cheaper per frame, noisier: more seeds
    const double sigma = std::sqrt(off.error * off.error + on.error * on.error);
    const double ray_ratio = on.rays / off.rays;
    std::printf(
        "roulette off %.5f ± %.5f, on %.5f ± %.5f, |diff| = %.2f sigma (tolerance %.2f %% of the mean); "
        "rays on/off %.3f\n",
        off.mean, off.error, on.mean, on.error, std::abs(on.mean - off.mean) / sigma, 100.0 * 4.5 * sigma / off.mean,
        ray_ratio);
    EXPECT_LT(4.5 * sigma, 0.01 * off.mean) << "too noisy to detect a bias of 1 %";
    EXPECT_NEAR(on.mean, off.mean, 4.5 * sigma);
    EXPECT_LT(ray_ratio, 0.6);
}

// The first bounce is never rouletted (kRouletteMinDepth = 1): with at most one bounce the
// switch changes no pixel and no ray count.
TEST(RendererRoulette, FirstBounceIsNeverEnded) {
    const Scene scene = roulette_scene();
    for (const int bounces : {0, 1}) {
        RgbFloatImage frames[2] = {RgbFloatImage({24, 16}), RgbFloatImage({24, 16})};
        std::uint64_t rays[2] = {0, 0};
        for (int roulette = 0; roulette < 2; ++roulette) {
            Renderer renderer(scene, options(roulette == 1));
            renderer.begin_frame(roulette_view(9, bounces));
            rays[roulette] = renderer.render(PixelRect::whole({24, 16}), frames[roulette]).rays;
        }
        EXPECT_EQ(rays[0], rays[1]) << bounces << " bounces";
        EXPECT_EQ(frames[0].pixels, frames[1].pixels) << bounces << " bounces";
    }
}

// A glossy sphere over a grey floor under a sky (plus a point light), 3 bounces with roulette: most
// of the light is the sky's, seen through bounces that escape. The sky's own ray at every vertex
// against the bounce ray's: the frame means over seeds agree within 4.5 standard deviations of their
// difference (that tolerance under 1 % of the mean, and the sky more than a third of the frame: a
// lost or doubled sky term moves the mean by far more), and fewer rays are traced.
TEST(RendererEnvironment, FromTheBounceMatchesItsOwnRayAndTracesFewerRays) {
    Scene scene = test::make_sphere_over_floor();
    scene.environment_lights = {EnvironmentLight{Rgb(0.6f, 0.7f, 0.9f)}};
    scene.point_lights = {PointLight{{1.0, 2.5, 1.0}, Rgb(1.5f, 1.2f, 1.0f), true}};
    const auto run = [&](bool from_bounce, int seeds, float sky) {
        Scene s = scene;
        s.environment_lights[0].radiance = Rgb(0.6f * sky, 0.7f * sky, 0.9f * sky);
        RendererOptions o = options(true);
        o.environment_from_bounce = from_bounce;
        Renderer renderer(s, o);
        std::vector<double> means;
        SeedMean out;
        for (int k = 0; k < seeds; ++k) {
            ViewRequest request = test::look_at({0.4, 1.6, 2.6}, {0.0, 0.8, 0.0}, {24, 16}, 70.0);
            request.quality.spp = 8;
            request.quality.max_bounces = 3;
            request.seed = 900u + static_cast<std::uint64_t>(k);
            renderer.begin_frame(request);
            RgbFloatImage frame(renderer.render_size());
            out.rays += static_cast<double>(renderer.render(PixelRect::whole(frame.size), frame).rays) / seeds;
            means.push_back(frame_mean(frame));
        }
        for (const double m : means) out.mean += m / static_cast<double>(seeds);
        double var = 0.0;
        for (const double m : means) var += (m - out.mean) * (m - out.mean);
        out.error = std::sqrt(var / static_cast<double>(seeds - 1) / static_cast<double>(seeds));
        return out;
    };
    const SeedMean own = run(false, 40, 1.0f);
    const SeedMean bounce = run(true, 40, 1.0f);
    const SeedMean no_sky = run(false, 8, 0.0f);
    const double sigma = std::sqrt(own.error * own.error + bounce.error * bounce.error);
    std::printf(
        "sky's own ray %.5f ± %.5f, from the bounce %.5f ± %.5f, |diff| = %.2f sigma (tolerance %.2f %% of "
        "the mean); without the sky %.5f; rays from the bounce / own %.3f\n",
        own.mean, own.error, bounce.mean, bounce.error, std::abs(bounce.mean - own.mean) / sigma,
        100.0 * 4.5 * sigma / own.mean, no_sky.mean, bounce.rays / own.rays);
    EXPECT_GT(own.mean - no_sky.mean, own.mean / 3.0) << "the sky must be a large part of the frame";
    EXPECT_LT(4.5 * sigma, 0.01 * own.mean) << "too noisy to detect a bias of 1 %";
    EXPECT_NEAR(bounce.mean, own.mean, 4.5 * sigma);
    EXPECT_LT(bounce.rays, 0.9 * own.rays);
}

// Without a bounce after a vertex (0 bounces), the switch changes nothing.
TEST(RendererEnvironment, WithoutBouncesTheSkyKeepsItsOwnRay) {
    Scene scene = test::make_sphere_over_floor();
    scene.environment_lights = {EnvironmentLight{}};
    RgbFloatImage frames[2] = {RgbFloatImage({24, 16}), RgbFloatImage({24, 16})};
    for (int from_bounce = 0; from_bounce < 2; ++from_bounce) {
        RendererOptions o = options(true);
        o.environment_from_bounce = from_bounce == 1;
        Renderer renderer(scene, o);
        ViewRequest request = test::look_at({0.4, 1.6, 2.6}, {0.0, 0.8, 0.0}, {24, 16}, 70.0);
        request.quality.spp = 4;
        renderer.begin_frame(request);
        (void)renderer.render(PixelRect::whole({24, 16}), frames[from_bounce]);
    }
    EXPECT_EQ(frames[0].pixels, frames[1].pixels);
}

// A wall lit to radiance 1 whose lower edge crosses pixel row 3 of an 8-row frame at py = 3.3:
// row 3 is 30 % covered (wall above the edge, black below), row 2 fully, row 4 not at all.
constexpr int kEdgeWidth = 64;
constexpr int kEdgeHeight = 8;
constexpr double kEdgeRowY = 3.3;
constexpr double kFovDeg = 60.0;

Scene edge_scene() {
    Scene scene;
    scene.source = "edge";
    scene.meshes.push_back(test::make_grid(4, 2000.0f, false));
    Material m;
    m.albedo = Rgb::Ones();
    scene.materials = {m};
    // Pinhole: a point (0, h, -10) from the eye is at py = H/2 (1 - (h/10) / tan(fov/2)).
    const double h = 10.0 * std::tan(kFovDeg * std::numbers::pi / 360.0) * (1.0 - kEdgeRowY / (kEdgeHeight / 2.0));
    Instance wall{"wall", 0, 0, Eigen::Affine3d::Identity()};  // the y = 0 grid turned to face +z
    wall.object_to_world.translate(Eigen::Vector3d(0.0, h + 2000.0, -10.0));
    wall.object_to_world.rotate(Eigen::AngleAxisd(std::numbers::pi / 2.0, Eigen::Vector3d::UnitX()));
    scene.instances = {wall};
    DirectionalLight sun;
    sun.direction_to_light = {0.0, 0.0, 1.0};
    sun.irradiance = Rgb::Constant(std::numbers::pi_v<float>);  // wall radiance 1
    sun.cast_shadows = false;
    scene.directional_lights = {sun};
    return scene;
}

ViewRequest edge_view(std::uint64_t frame_id) {
    ViewRequest request = test::look_at({0.0, 0.0, 0.0}, {0.0, 0.0, -1.0}, {kEdgeWidth, kEdgeHeight}, kFovDeg);
    request.quality.spp = 1;
    request.seed = 3;
    request.frame_id = frame_id;
    return request;
}

// The mean of `passes` 1-spp frames (frame ids 0..passes-1), as the farm accumulates a still view.
RgbFloatImage accumulate_one_spp(bool jitter, int passes) {
    const Scene scene = edge_scene();
    Renderer renderer(scene, options(true, jitter));
    RgbFloatImage sum({kEdgeWidth, kEdgeHeight}, 0.0f);
    RgbFloatImage frame({kEdgeWidth, kEdgeHeight});
    for (int pass = 0; pass < passes; ++pass) {
        renderer.begin_frame(edge_view(static_cast<std::uint64_t>(pass)));
        renderer.render(PixelRect::whole(frame.size), frame);
        for (std::size_t i = 0; i < frame.pixels.size(); ++i)
            sum.pixels[i] += frame.pixels[i] / static_cast<float>(passes);
    }
    return sum;
}

double row_mean(const RgbFloatImage& f, int y) {
    double sum = 0.0;
    for (int x = 0; x < f.size.width; ++x) sum += f.at(x, y)[0];
    return sum / f.size.width;
}

// 64 passes: each pixel of row 3 averages 64 Bernoulli(0.3) samples (standard deviation 0.057), the
// row 4096 (0.0072): the row must read 0.3 within 0.03 (4 sigma), and every pixel of it must be
// strictly between 0 and 1 (all 64 samples on one side: probability 0.7^64 < 1e-9). Pixel centres
// (the baseline) read exactly 0 there, whatever the number of passes.
TEST(RendererJitter, OneSppPassesConvergeToTheCoveredFractionAtAnEdge) {
    const RgbFloatImage jittered = accumulate_one_spp(true, 64);
    const RgbFloatImage centred = accumulate_one_spp(false, 64);
    std::printf("edge row (30 %% covered) over 64 one-spp passes: jittered %.4f, pixel centres %.4f\n",
                row_mean(jittered, 3), row_mean(centred, 3));
    EXPECT_NEAR(row_mean(jittered, 3), kEdgeRowY - 3.0, 0.03);
    for (int x = 0; x < kEdgeWidth; ++x) {
        EXPECT_GT(jittered.at(x, 3)[0], 0.0f) << "pixel " << x;
        EXPECT_LT(jittered.at(x, 3)[0], 1.0f) << "pixel " << x;
        EXPECT_NEAR(jittered.at(x, 2)[0], 1.0f, 1e-4f) << "pixel " << x;
        EXPECT_EQ(jittered.at(x, 4)[0], 0.0f) << "pixel " << x;
    }
    EXPECT_EQ(row_mean(centred, 3), 0.0) << "pixel centres lie below the edge";
}

// Same seed and frame id: the same bytes; another seed or frame id: other sub-pixel positions.
TEST(RendererJitter, OneSppPositionsAreDeterministicPerSeedAndFrame) {
    const Scene scene = edge_scene();
    Renderer renderer(scene, options(true));
    const auto render = [&](std::uint64_t seed, std::uint64_t frame_id) {
        ViewRequest request = edge_view(frame_id);
        request.seed = seed;
        renderer.begin_frame(request);
        RgbFloatImage frame(renderer.render_size());
        renderer.render(PixelRect::whole(frame.size), frame);
        return frame.pixels;
    };
    const std::vector<float> a = render(3, 0);
    EXPECT_EQ(a, render(3, 0));
    EXPECT_NE(a, render(4, 0));
    EXPECT_NE(a, render(3, 1));
}

}  // namespace
}  // namespace mogao
