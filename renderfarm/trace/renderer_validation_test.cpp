// SPDX-License-Identifier: Apache-2.0
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "renderfarm/trace/renderer.h"
#include "renderfarm/trace/test_scenes.h"

namespace mogao {
namespace {

TEST(RendererValidation, BeginFrameRenderAndSizeErrors) {
    const Scene scene = test::make_sphere_over_floor();
    Renderer renderer(scene, RendererOptions{"threads=1", true});
    EXPECT_THROW((void)renderer.render_size(), std::logic_error);
    RgbFloatImage frame({8, 8});
    EXPECT_THROW(renderer.render({0, 0, 8, 8}, frame), std::logic_error);

    ViewRequest bad;
    bad.quality.spp = 0;
    EXPECT_THROW(renderer.begin_frame(bad), std::invalid_argument);

    ViewRequest request;
    request.size = {40, 30};
    request.quality.resolution_scale = 0.5;
    renderer.begin_frame(request);
    EXPECT_EQ(renderer.render_size(), (ImageSize{20, 15}));
    RgbFloatImage wrong({40, 30});
    EXPECT_THROW(renderer.render({0, 0, 4, 4}, wrong), std::invalid_argument);
    RgbFloatImage right(renderer.render_size());
    EXPECT_THROW(renderer.render({0, 0, 21, 4}, right), std::invalid_argument);
    EXPECT_THROW(renderer.render({-1, 0, 4, 4}, right), std::invalid_argument);
    EXPECT_NO_THROW(renderer.render({0, 0, 20, 15}, right));
    EXPECT_EQ(renderer.render({3, 3, 3, 9}, right).rays, 0u);  // empty rect

    // A rejected request leaves the previous frame current.
    EXPECT_THROW(renderer.begin_frame(bad), std::invalid_argument);
    EXPECT_EQ(renderer.render_size(), (ImageSize{20, 15}));
}

TEST(RendererValidation, RejectsInconsistentScenes) {
    Scene scene = test::make_sphere_over_floor();
    scene.instances[0].material = 5;
    EXPECT_THROW(Renderer(scene, RendererOptions{"threads=1", true}), std::invalid_argument);
    scene = test::make_sphere_over_floor();
    scene.meshes[1].triangles[3][1] = 100000;
    EXPECT_THROW(Renderer(scene, RendererOptions{"threads=1", true}), std::invalid_argument);
    scene = test::make_sphere_over_floor();
    scene.instances[1].object_to_world.linear().setZero();
    EXPECT_THROW(Renderer(scene, RendererOptions{"threads=1", true}), std::invalid_argument);
    scene = test::make_sphere_over_floor();
    scene.area_lights = {AreaLight{{0.0, 2.0, 0.0}, {1.0, 0.0, 0.0}, {2.0, 0.0, 0.0}, Rgb(1.0f, 1.0f, 1.0f), true}};
    EXPECT_THROW(Renderer(scene, RendererOptions{"threads=1", true}), std::invalid_argument);
}

}  // namespace
}  // namespace mogao
