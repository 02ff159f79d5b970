// SPDX-License-Identifier: Apache-2.0
// A pixel's value may depend only on (scene, request, x, y): rendering a frame as one rect, as
// many rects (in any order, on several threads) or again must give bit-identical buffers.
#include <algorithm>
#include <cstring>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "renderfarm/trace/renderer.h"
#include "renderfarm/trace/test_scenes.h"

namespace mogao {
namespace {

Scene lit_scene() {
    Scene scene = test::make_sphere_over_floor();
    DirectionalLight sun;
    sun.direction_to_light = Eigen::Vector3d(-0.4, 1.0, 0.3).normalized();
    scene.directional_lights = {sun};
    scene.point_lights = {PointLight{{1.0, 2.0, 1.0}, Rgb(4.0f, 4.0f, 4.0f), true}};
    scene.area_lights = {AreaLight{{-0.5, 2.5, -0.5}, {1.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, Rgb(3.0f, 3.0f, 3.0f), true}};
    // edge_u x edge_v = x x z = -y: the area light shines down.
    scene.environment_lights = {EnvironmentLight{Rgb(0.2f, 0.2f, 0.25f)}};
    return scene;
}

ViewRequest noisy_request() {
    ViewRequest request = test::look_at({0.3, 2.0, 3.5}, {0.0, 0.6, 0.0}, {72, 56}, 50.0);
    request.quality.spp = 4;
    request.quality.ao_samples = 2;
    request.quality.max_bounces = 2;
    request.quality.area_light_samples = 2;
    request.seed = 1234;
    request.frame_id = 7;
    return request;
}

// Splits `rect` recursively at random multiples of `align` until pieces are small.
void random_split(const PixelRect& rect, int align, std::mt19937& rng, std::vector<PixelRect>& out) {
    const bool split_x = rect.width() >= rect.height();
    const int lo = split_x ? rect.x0 : rect.y0;
    const int hi = split_x ? rect.x1 : rect.y1;
    const int first = (lo / align + 1) * align;
    if (rect.area() <= 200 || first >= hi) {
        out.push_back(rect);
        return;
    }
    std::uniform_int_distribution<int> pick(first / align, (hi - 1) / align);
    const int cut = pick(rng) * align;
    PixelRect a = rect;
    PixelRect b = rect;
    (split_x ? a.x1 : a.y1) = cut;
    (split_x ? b.x0 : b.y0) = cut;
    random_split(a, align, rng, out);
    random_split(b, align, rng, out);
}

bool identical(const RgbFloatImage& a, const RgbFloatImage& b) {
    return a.size == b.size && std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(float)) == 0;
}

class RendererDeterminism : public ::testing::TestWithParam<int> {};

TEST_P(RendererDeterminism, RectSplitsAndThreadsGiveBitIdenticalFrames) {
    const int align = GetParam();
    const Scene scene = lit_scene();
    Renderer renderer(scene, RendererOptions{"threads=1", true});
    renderer.begin_frame(noisy_request());
    const ImageSize size = renderer.render_size();

    RgbFloatImage whole(size, -1.0f);
    const TileStats whole_stats = renderer.render(PixelRect::whole(size), whole);
    EXPECT_GT(whole_stats.rays, static_cast<std::uint64_t>(size.pixel_count()) * 4);  // secondary rays traced

    std::mt19937 rng(42u + static_cast<unsigned>(align));
    std::vector<PixelRect> rects;
    random_split(PixelRect::whole(size), align, rng, rects);
    ASSERT_GT(rects.size(), 8u);
    std::shuffle(rects.begin(), rects.end(), rng);

    RgbFloatImage pieces(size, -1.0f);
    std::uint64_t piece_rays = 0;
    std::vector<std::uint64_t> rays_per_thread(2, 0);
    std::vector<std::thread> threads;
    for (std::size_t t = 0; t < 2; ++t) {
        threads.emplace_back([&, t] {
            for (std::size_t i = t; i < rects.size(); i += 2)
                rays_per_thread[t] += renderer.render(rects[i], pieces).rays;
        });
    }
    for (auto& thread : threads) thread.join();
    for (const auto r : rays_per_thread) piece_rays += r;
    EXPECT_TRUE(identical(whole, pieces)) << "rect split aligned to " << align << " px changed pixels";
    EXPECT_EQ(piece_rays, whole_stats.rays);
}

INSTANTIATE_TEST_SUITE_P(Alignments, RendererDeterminism, ::testing::Values(8, 1));

TEST(RendererDeterminismSeed, SameSeedSameFrameOtherSeedOtherNoise) {
    const Scene scene = lit_scene();
    Renderer renderer(scene, RendererOptions{"threads=1", true});
    ViewRequest request = noisy_request();
    renderer.begin_frame(request);
    RgbFloatImage a(renderer.render_size());
    RgbFloatImage b(renderer.render_size());
    renderer.render(PixelRect::whole(a.size), a);
    renderer.render(PixelRect::whole(b.size), b);
    EXPECT_TRUE(identical(a, b));

    request.seed = 99;
    renderer.begin_frame(request);
    RgbFloatImage c(renderer.render_size());
    renderer.render(PixelRect::whole(c.size), c);
    EXPECT_FALSE(identical(a, c)) << "the seed must change the noise";
}

TEST(RendererDeterminismSeed, RenderWritesOnlyInsideRect) {
    const Scene scene = lit_scene();
    Renderer renderer(scene, RendererOptions{"threads=1", true});
    renderer.begin_frame(noisy_request());
    RgbFloatImage frame(renderer.render_size(), -7.0f);
    const PixelRect rect{5, 3, 23, 17};  // deliberately not 4-aligned
    const TileStats stats = renderer.render(rect, frame);
    EXPECT_GE(stats.rays, static_cast<std::uint64_t>(rect.area()) * 4);
    for (int y = 0; y < frame.size.height; ++y) {
        for (int x = 0; x < frame.size.width; ++x) {
            const float v = frame.at(x, y)[0];
            if (rect.contains(x, y)) {
                EXPECT_GE(v, 0.0f) << x << "," << y;
            } else {
                EXPECT_EQ(v, -7.0f) << x << "," << y;
            }
        }
    }
}

// A rank renders into windows of its share (tile_pass.h): every rect rendered into a window of its
// own size, at an odd origin, gives the very bytes of the whole-frame render; a window that does
// not contain the rect is refused, naming both.
TEST(RendererDeterminismSeed, WindowRenderIsBitIdenticalToTheWholeFrame) {
    const Scene scene = lit_scene();  // the renderer keeps referring to the scene's meshes
    Renderer renderer(scene);
    renderer.begin_frame(noisy_request());
    const ImageSize size = renderer.render_size();
    RgbFloatImage whole(size);
    renderer.render(PixelRect::whole(size), whole);
    std::mt19937 rng(5);
    std::vector<PixelRect> rects;
    random_split(PixelRect::whole(size), 1, rng, rects);  // any alignment, as tiles clipped to rects are
    ASSERT_GT(rects.size(), 4u);
    for (const PixelRect& r : rects) {
        RgbFloatImage window({r.width(), r.height()}, -1.0f);
        renderer.render(r, window, r.x0, r.y0);
        for (int y = r.y0; y < r.y1; ++y)
            ASSERT_EQ(std::memcmp(window.at(0, y - r.y0), whole.at(r.x0, y), sizeof(float) * 3 * r.width()), 0)
                << "rect row " << y;
    }
    const PixelRect r{8, 8, 24, 20};
    RgbFloatImage small({16, 11}, 0.0f);  // one row short
    try {
        renderer.render(r, small, 8, 8);
        ADD_FAILURE() << "a window one row short was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("outside the window"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace mogao
