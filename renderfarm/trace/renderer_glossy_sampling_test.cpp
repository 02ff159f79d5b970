// SPDX-License-Identifier: Apache-2.0
// Glossy bounces from GGX visible normals mixed with the cosine lobe (RendererOptions::
// glossy_vndf_sampling, integrator.h) must converge to what cosine sampling converges to, and a
// white furnace must not gain energy:
//  * the visible-normal pdf integrates to 1 over the hemisphere and matches the sampled histogram;
//  * a glossy floor and sphere under an area light (MIS with the mixture pdf), a point light and a
//    sky: frame means over seeds with and without agree within the measured tolerance;
//  * a glossy sphere (k_s 1) over a white floor (albedo 1) under a uniform sky L, 8 bounces: the
//    frame mean with visible normals agrees with cosine sampling and neither exceeds L.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "renderfarm/trace/renderer.h"
#include "renderfarm/trace/sampling.h"
#include "renderfarm/trace/shading.h"
#include "renderfarm/trace/sobol.h"
#include "renderfarm/trace/test_scenes.h"

namespace mogao {
namespace {

// ∫ pdf(wi) dωi over the hemisphere by a midpoint rule in (cosθ, φ), at several views and
// roughnesses: the fraction of sampled reflections that stay above the horizon (the rest, h
// sampled but wi under n, end the path: a third of them at α = 0.7, measured), never above 1.
TEST(GgxVisibleNormals, ReflectionPdfIntegratesToAtMostOneAndSamplesFollowIt) {
    const Eigen::Vector3f n = Eigen::Vector3f::UnitZ();
    for (const float alpha : {0.1f, 0.3f, 0.7f}) {
        for (const float theta_o : {0.0f, 0.6f, 1.2f}) {
            const Eigen::Vector3f wo(std::sin(theta_o), 0.0f, std::cos(theta_o));
            constexpr int kSteps = 1200;
            double integral = 0.0;
            for (int i = 0; i < kSteps; ++i) {
                const double c = (i + 0.5) / kSteps;
                for (int j = 0; j < kSteps / 4; ++j) {
                    const double phi = 2.0 * std::numbers::pi * (j + 0.5) / (kSteps / 4);
                    const double s = std::sqrt(1.0 - c * c);
                    const Eigen::Vector3f wi(static_cast<float>(s * std::cos(phi)),
                                             static_cast<float>(s * std::sin(phi)), static_cast<float>(c));
                    integral +=
                        ggx_reflection_pdf(n, wo, wi, alpha) * (1.0 / kSteps) * (2.0 * std::numbers::pi / (kSteps / 4));
                }
            }
            // The fraction of sampled reflections above the horizon must equal the integral.
            int above = 0;
            constexpr int kSamples = 20000;
            for (int k = 0; k < kSamples; ++k) {
                const Eigen::Vector2f u = owen_sobol_2d(static_cast<std::uint32_t>(k), 17);
                const Eigen::Vector3f h = ggx_visible_normal(wo, alpha, u.x(), u.y());
                above += (2.0f * wo.dot(h) * h - wo).z() > 0.0f ? 1 : 0;
            }
            const double fraction = static_cast<double>(above) / kSamples;
            std::printf("alpha %.1f theta_o %.1f: integral of pdf %.4f, sampled fraction above %.4f\n", alpha, theta_o,
                        integral, fraction);
            EXPECT_LE(integral, 1.0 + 5e-3);
            EXPECT_GE(integral, 0.6);
            EXPECT_NEAR(integral, fraction, 0.01);
        }
    }
}

RendererOptions options(bool vndf) {
    RendererOptions o{"threads=1", true};
    o.glossy_vndf_sampling = vndf;
    o.legacy_light_sampling = false;  // light selection: the area light is combined with bounces by MIS
    return o;
}

struct SeedMean {
    double mean = 0.0;
    double error = 0.0;  // standard error over seeds
};

SeedMean over_seeds(const Scene& scene, ViewRequest view, bool vndf, int seeds) {
    Renderer renderer(scene, options(vndf));
    std::vector<double> means;
    for (int s = 0; s < seeds; ++s) {
        view.seed = 700u + static_cast<std::uint64_t>(s);
        renderer.begin_frame(view);
        RgbFloatImage frame(renderer.render_size());
        renderer.render(PixelRect::whole(frame.size), frame);
        double sum = 0.0;
        for (const float v : frame.pixels) sum += v;
        means.push_back(sum / static_cast<double>(frame.pixels.size()));
    }
    SeedMean out;
    for (const double m : means) out.mean += m;
    out.mean /= seeds;
    double var = 0.0;
    for (const double m : means) var += (m - out.mean) * (m - out.mean);
    out.error = std::sqrt(var / (seeds - 1) / seeds);
    return out;
}

// Tolerance as in the roulette test (renderer_sampling_test.cpp): 4.5 standard deviations of the
// difference of the two means, measured from the seeds, and that tolerance under 2 % of the mean
// (32 spp x 40 seeds per estimator keep each test near a second; measured 1.2-1.3 %).
void expect_same_mean(const Scene& scene, const ViewRequest& view, const char* what, double* mean_out = nullptr) {
    const SeedMean cosine = over_seeds(scene, view, false, 40);
    const SeedMean vndf = over_seeds(scene, view, true, 40);
    const double sigma = std::sqrt(cosine.error * cosine.error + vndf.error * vndf.error);
    std::printf(
        "%s: cosine %.5f ± %.5f, visible normals %.5f ± %.5f, |diff| = %.2f sigma (tolerance %.2f %%); "
        "per-seed spread visible/cosine %.2f\n",
        what, cosine.mean, cosine.error, vndf.mean, vndf.error, std::abs(vndf.mean - cosine.mean) / sigma,
        100.0 * 4.5 * sigma / cosine.mean, vndf.error / cosine.error);
    EXPECT_LT(4.5 * sigma, 0.02 * cosine.mean) << what << ": too noisy to detect a bias of 2 %";
    EXPECT_NEAR(vndf.mean, cosine.mean, 4.5 * sigma) << what;
    if (mean_out != nullptr) {
        mean_out[0] = cosine.mean - 4.5 * cosine.error;  // the lowest mean each run allows
        mean_out[1] = vndf.mean - 4.5 * vndf.error;
    }
}

// A sharp glossy floor (s = 200) and the glossy sphere of the test scene under an area light, a
// point light and a sky, 2 bounces: the area light is reached both by light samples and by
// glossy bounces, weighted by the mixture pdf.
TEST(RendererGlossySampling, VisibleNormalsMatchCosineSamplingWithAreaLightMis) {
    Scene scene = test::make_sphere_over_floor();
    Material floor;
    floor.albedo = Rgb(0.5f, 0.5f, 0.5f);
    floor.specular = Rgb(0.5f, 0.5f, 0.5f);
    floor.shininess = 200.0f;
    scene.materials[0] = floor;
    scene.point_lights = {PointLight{{1.0, 2.0, 1.0}, Rgb(2.0f, 1.5f, 1.0f), true}};
    scene.area_lights = {AreaLight{{-0.5, 2.5, -0.5}, {1.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, Rgb(3.0f, 3.0f, 3.0f), true}};
    scene.environment_lights = {EnvironmentLight{Rgb(0.2f, 0.2f, 0.25f)}};
    ViewRequest view = test::look_at({0.3, 2.0, 3.5}, {0.0, 0.6, 0.0}, {24, 16}, 50.0);
    view.quality.spp = 32;
    view.quality.max_bounces = 2;
    expect_same_mean(scene, view, "glossy floor, area light");
}

// White furnace: nothing absorbs but the glossy lobe's single-scattering loss, so no pixel can be
// brighter than the sky L = 1 and the frame mean (sky pixels included) stays at or under 1.
TEST(RendererGlossySampling, GlossyFurnaceAgreesWithCosineSamplingAndNeverExceedsTheSky) {
    Scene scene = test::make_sphere_over_floor();
    Material white;
    white.albedo = Rgb::Ones();
    Material mirror_like;
    mirror_like.albedo = Rgb::Ones();
    mirror_like.specular = Rgb::Ones();  // pure GGX
    mirror_like.shininess = 100.0f;
    scene.materials = {white, mirror_like};
    scene.environment_lights = {EnvironmentLight{Rgb::Ones()}};
    ViewRequest view = test::look_at({0.3, 1.2, 2.0}, {0.0, 0.7, 0.0}, {24, 16}, 60.0);
    view.quality.spp = 32;
    view.quality.max_bounces = 8;
    double lowest[2] = {0.0, 0.0};
    expect_same_mean(scene, view, "glossy furnace", lowest);
    EXPECT_LE(lowest[0], 1.0) << "cosine sampling gains energy";
    EXPECT_LE(lowest[1], 1.0) << "visible-normal sampling gains energy";
}

}  // namespace
}  // namespace mogao
