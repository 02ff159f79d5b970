// SPDX-License-Identifier: Apache-2.0
// Precision far from the world origin: the same scene and camera moved by (1e5, 0, -1e5) m must
// render the same image, thanks to rebasing the world on the eye every frame (render_scene.h).
#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "renderfarm/trace/renderer.h"
#include "renderfarm/trace/test_scenes.h"

namespace mogao {
namespace {

Scene lit_scene_at(const Eigen::Vector3d& offset) {
    Scene scene = test::make_sphere_over_floor(offset);
    DirectionalLight sun;
    sun.direction_to_light = Eigen::Vector3d(-0.4, 1.0, 0.3).normalized();
    scene.directional_lights = {sun};
    scene.point_lights = {PointLight{offset + Eigen::Vector3d(1.0, 2.0, 1.0), Rgb(4.0f, 4.0f, 4.0f), true}};
    scene.area_lights = {AreaLight{
        offset + Eigen::Vector3d(-0.5, 2.5, -0.5), {1.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, Rgb(3.0f, 3.0f, 3.0f), true}};
    scene.environment_lights = {EnvironmentLight{Rgb(0.2f, 0.2f, 0.25f)}};
    return scene;
}

RgbFloatImage render_at(const Eigen::Vector3d& offset, bool rebase) {
    const Scene scene = lit_scene_at(offset);
    Renderer renderer(scene, RendererOptions{"threads=1", rebase});
    ViewRequest request =
        test::look_at(offset + Eigen::Vector3d(0.3, 2.0, 3.5), offset + Eigen::Vector3d(0.0, 0.6, 0.0), {64, 48}, 50.0);
    request.quality.spp = 2;
    request.quality.ao_samples = 2;
    request.quality.max_bounces = 1;
    renderer.begin_frame(request);
    RgbFloatImage frame(renderer.render_size());
    renderer.render(PixelRect::whole(frame.size), frame);
    return frame;
}

double mean_abs_diff(const RgbFloatImage& a, const RgbFloatImage& b) {
    double sum = 0.0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) sum += std::abs(static_cast<double>(a.pixels[i]) - b.pixels[i]);
    return sum / static_cast<double>(a.pixels.size());
}

double mean(const RgbFloatImage& a) {
    double sum = 0.0;
    for (const float v : a.pixels) sum += v;
    return sum / static_cast<double>(a.pixels.size());
}

TEST(RendererFarOrigin, TranslatedSceneRendersTheSameImage) {
    const Eigen::Vector3d far(1e5, 0.0, -1e5);
    const RgbFloatImage near_image = render_at(Eigen::Vector3d::Zero(), true);
    const RgbFloatImage far_image = render_at(far, true);
    const double level = mean(near_image);
    ASSERT_GT(level, 0.01);
    // Tolerance: mean |difference| <= 1e-4 of the mean radiance (float rounding of the rebased
    // transforms; a rare shadow/AO ray may flip at a silhouette).
    const double diff = mean_abs_diff(near_image, far_image);
    EXPECT_LE(diff, 1e-4 * level) << "mean abs diff " << diff << " vs mean " << level;
    RecordProperty("mean_abs_diff_relative", std::to_string(diff / level));
    std::printf("far origin: mean |diff| / mean = %.3g (rebased)\n", diff / level);

    // Control: without rebasing, float coordinates near 1e5 m (ULP 7.8 mm) visibly change the image,
    // so the check above is not vacuous.
    const RgbFloatImage unrebased = render_at(far, false);
    const double control = mean_abs_diff(near_image, unrebased);
    std::printf("far origin: mean |diff| / mean = %.3g (not rebased)\n", control / level);
    EXPECT_GT(control, 10.0 * 1e-4 * level);
}

}  // namespace
}  // namespace mogao
