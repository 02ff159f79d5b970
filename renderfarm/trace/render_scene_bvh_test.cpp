// SPDX-License-Identifier: Apache-2.0
// BVH choices (BvhOptions, render_scene.h): flattening the static instances into one BLAS renders
// the frame the two-level BVH renders (hit points differ by float rounding only), which instances it
// flattens follows the copies' size, and a watertight scene is never flattened.
#include <cmath>
#include <cstdio>
#include <numbers>

#include <gtest/gtest.h>

#include "renderfarm/trace/render_scene.h"
#include "renderfarm/trace/renderer.h"
#include "renderfarm/trace/test_scenes.h"

namespace mogao {
namespace {

// The sphere-over-floor scene with a second sphere placed rotated, non-uniformly scaled and away from
// the origin (so a wrong normal transform or anchor shows), lit by a shadowing point light and a sky.
Scene two_spheres() {
    Scene scene = test::make_sphere_over_floor(Eigen::Vector3d(40.0, 0.0, -25.0));
    Instance second{"second sphere", 0, 0, Eigen::Affine3d::Identity()};
    second.object_to_world.translate(Eigen::Vector3d(40.9, 0.6, -25.4));
    second.object_to_world.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, 2.0, 0.5).normalized()));
    second.object_to_world.scale(Eigen::Vector3d(1.4, 0.6, 0.9));
    scene.instances.push_back(second);
    PointLight light;
    light.position = Eigen::Vector3d(41.5, 3.0, -23.5);
    scene.point_lights.push_back(light);
    scene.environment_lights.push_back(EnvironmentLight{});
    return scene;
}

RgbFloatImage render(const Scene& scene, bool flatten, std::size_t* flattened) {
    RendererOptions options{"threads=1"};
    options.bvh.flatten = flatten;
    Renderer renderer(scene, options);
    *flattened = renderer.render_scene().flattened_instances();
    ViewRequest view = test::look_at({38.2, 2.2, -21.8}, {40.4, 0.7, -25.2}, {96, 72}, 50.0);
    view.quality.spp = 2;
    view.quality.max_bounces = 2;
    renderer.begin_frame(view);
    RgbFloatImage frame(renderer.render_size());
    (void)renderer.render(PixelRect::whole(frame.size), frame);
    return frame;
}

TEST(RenderSceneBvh, FlattenedAndInstancedBvhsRenderTheSameFrame) {
    const Scene scene = two_spheres();
    std::size_t flat_count = 0, instanced_count = 0;
    const RgbFloatImage flat = render(scene, true, &flat_count);
    const RgbFloatImage instanced = render(scene, false, &instanced_count);
    EXPECT_EQ(flat_count, 3u);
    EXPECT_EQ(instanced_count, 0u);
    ASSERT_EQ(flat.pixels.size(), instanced.pixels.size());
    double sum = 0.0, diff = 0.0;
    int differing = 0;
    for (std::size_t i = 0; i < flat.pixels.size(); ++i) {  // channels of every pixel
        const double d = std::abs(double(flat.pixels[i]) - double(instanced.pixels[i]));
        sum += std::abs(double(instanced.pixels[i]));
        diff += d;
        if (d > 1e-3 * (1.0 + std::abs(double(instanced.pixels[i])))) ++differing;
    }
    std::printf("mean |flattened - instanced| / mean radiance %.3g, channels off by > 1e-3: %d of %zu\n", diff / sum,
                differing, flat.pixels.size());
    EXPECT_GT(sum, 0.0);
    EXPECT_LT(diff / sum, 1e-4);  // a normal in the wrong frame or a misplaced copy is percents off
    EXPECT_LE(differing, static_cast<int>(flat.pixels.size() / 200));  // rounding may flip a shadow ray at an edge
}

TEST(RenderSceneBvh, AMeshWhoseCopiesWouldBeLargeStaysInstanced) {
    const Scene scene = two_spheres();  // the sphere placed twice, the floor once
    const std::size_t copies = 2 * scene.meshes[0].triangle_count();
    BvhOptions bvh;
    bvh.flatten_max_triangles = copies - 1;
    EXPECT_EQ(RenderScene(scene, "threads=1", bvh).flattened_instances(), 1u);  // the floor
    bvh.flatten_max_triangles = copies;
    EXPECT_EQ(RenderScene(scene, "threads=1", bvh).flattened_instances(), 3u);
}

TEST(RenderSceneBvh, AWatertightSceneIsNeverFlattened) {
    Scene scene = two_spheres();
    scene.robust_intersection = true;
    EXPECT_EQ(RenderScene(scene, "threads=1").flattened_instances(), 0u);
}

}  // namespace
}  // namespace mogao
