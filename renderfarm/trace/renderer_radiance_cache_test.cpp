// SPDX-License-Identifier: Apache-2.0
// Cached frames (cached_packet.h) against the unbiased path tracer of the same scene: close to its
// converged reference (the cache's bias is bounded), closer than a 1-spp path-traced frame, fewer
// rays, the same bits for any split of a frame into rects, and frames that do not ask for the
// cache untouched by it.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "renderfarm/trace/renderer.h"
#include "renderfarm/trace/test_scenes.h"

namespace mogao {
namespace {

// A sphere on a floor before a wall, lit by two point lights and a sky: light bounces between the
// three, so the cache's part (the sky and the bounces) is a large share of every pixel.
Scene lit_corner() {
    Scene scene = test::make_sphere_over_floor();
    Eigen::Affine3d wall = Eigen::Affine3d::Identity();
    wall.translate(Eigen::Vector3d(0.0, 2.0, -2.0));
    wall.rotate(Eigen::AngleAxisd(M_PI / 2.0, Eigen::Vector3d::UnitX()));
    scene.instances.push_back(Instance{"wall", 1, 0, wall});
    scene.point_lights = {PointLight{{1.0, 2.5, 1.5}, Rgb(6.0f, 6.0f, 6.0f), true},
                          PointLight{{-1.5, 1.5, 1.0}, Rgb(2.0f, 1.5f, 1.0f), true}};
    scene.environment_lights = {EnvironmentLight{Rgb(0.3f, 0.3f, 0.35f)}};
    return scene;
}

ViewRequest corner_view(std::uint64_t frame_id, int spp, bool cached) {
    ViewRequest r = test::look_at({0.3, 1.4, 3.2}, {0.0, 0.7, 0.0}, {64, 48}, 55.0);
    r.frame_id = frame_id;
    r.quality.spp = spp;
    r.quality.max_bounces = 2;
    r.radiance_cache = cached;
    return r;
}

RgbFloatImage draw(Renderer& renderer, const ViewRequest& request, std::uint64_t* rays = nullptr) {
    renderer.begin_frame(request);
    RgbFloatImage frame(renderer.render_size());
    const TileStats stats = renderer.render(PixelRect::whole(frame.size), frame);
    if (rays != nullptr) *rays = stats.rays;
    return frame;
}

double mean(const RgbFloatImage& f) {
    double sum = 0.0;
    for (const float v : f.pixels) sum += v;
    return sum / static_cast<double>(f.pixels.size());
}

// Mean squared error relative to the reference's mean square (an image-wide relMSE).
double rel_mse(const RgbFloatImage& f, const RgbFloatImage& ref) {
    double err = 0.0;
    double norm = 0.0;
    for (std::size_t i = 0; i < f.pixels.size(); ++i) {
        const double d = f.pixels[i] - ref.pixels[i];
        err += d * d;
        norm += static_cast<double>(ref.pixels[i]) * ref.pixels[i];
    }
    return err / norm;
}

TEST(RendererRadianceCache, WarmCachedFramesAreCloseToTheReferenceAndBeatOneSample) {
    const Scene scene = lit_corner();
    Renderer reference_renderer(scene, RendererOptions{"threads=1", true});
    const RgbFloatImage reference = draw(reference_renderer, corner_view(1000, 256, false));
    const RgbFloatImage one_spp = draw(reference_renderer, corner_view(2000, 1, false));

    Renderer renderer(scene, RendererOptions{"threads=1", true});
    for (std::uint64_t f = 1; f <= 32; ++f) (void)draw(renderer, corner_view(f, 1, true));
    const RgbFloatImage cached = draw(renderer, corner_view(33, 1, true));
    EXPECT_GT(renderer.radiance_cache_stats().cells, 100u);

    const double bias = mean(cached) / mean(reference) - 1.0;
    EXPECT_LT(std::abs(bias), 0.05) << "the cached frame's mean is " << 100.0 * bias << " % off the reference's";
    const double cached_error = rel_mse(cached, reference);
    const double one_spp_error = rel_mse(one_spp, reference);
    EXPECT_LT(cached_error, 0.5 * one_spp_error)
        << "relMSE cached " << cached_error << ", path-traced 1 spp " << one_spp_error;
}

TEST(RendererRadianceCache, AWarmCacheTracesFewerRaysThanThePathTracer) {
    const Scene scene = lit_corner();
    Renderer renderer(scene, RendererOptions{"threads=1", true});
    for (std::uint64_t f = 1; f <= 16; ++f) (void)draw(renderer, corner_view(f, 1, true));
    std::uint64_t cached_rays = 0;
    std::uint64_t traced_rays = 0;
    (void)draw(renderer, corner_view(17, 1, true), &cached_rays);
    (void)draw(renderer, corner_view(17, 1, false), &traced_rays);
    // Per pixel the cache saves the environment ray and every bounce with its shadow rays, and the
    // shadow rays towards the lights wherever the pixel's cell knows them.
    EXPECT_LT(static_cast<double>(cached_rays), 0.7 * static_cast<double>(traced_rays))
        << cached_rays << " rays cached, " << traced_rays << " path-traced";
}

// Shadow rays towards lights a cell knows are skipped: fewer rays, and the frame stays as close to
// the reference as with every shadow ray traced (its bias: shadows smaller than a cell missed).
TEST(RendererRadianceCache, KnownLightsAreNotTracedAndTheFrameStaysClose) {
    const Scene scene = lit_corner();
    Renderer reference_renderer(scene, RendererOptions{"threads=1", true});
    const RgbFloatImage reference = draw(reference_renderer, corner_view(1000, 256, false));
    RendererOptions all_traced{"threads=1", true};
    all_traced.radiance_cache.visibility_min_samples = 0;
    Renderer gated(scene, RendererOptions{"threads=1", true});
    Renderer traced(scene, all_traced);
    for (std::uint64_t f = 1; f <= 16; ++f) {
        (void)draw(gated, corner_view(f, 1, true));
        (void)draw(traced, corner_view(f, 1, true));
    }
    std::uint64_t gated_rays = 0;
    std::uint64_t traced_rays = 0;
    const RgbFloatImage a = draw(gated, corner_view(17, 1, true), &gated_rays);
    const RgbFloatImage b = draw(traced, corner_view(17, 1, true), &traced_rays);
    EXPECT_LT(static_cast<double>(gated_rays), 0.8 * static_cast<double>(traced_rays))
        << gated_rays << " rays with visibility, " << traced_rays << " without";
    const double gated_error = rel_mse(a, reference);
    const double traced_error = rel_mse(b, reference);
    EXPECT_LT(gated_error, 1.25 * traced_error)
        << "relMSE " << gated_error << " with visibility, " << traced_error << " with every shadow ray traced";
    EXPECT_LT(std::abs(mean(a) / mean(b) - 1.0), 0.02);
}

// Diffuse pixels in cells that know every light take the lights' direct light from the cell
// (RadianceCacheOptions::cache_direct): the frame changes, and stays as close to the reference as
// with the direct light traced at every pixel (its bias: the direct light constant over a cell).
TEST(RendererRadianceCache, DirectLightFromSettledCellsKeepsTheFrameClose) {
    const Scene scene = lit_corner();
    Renderer reference_renderer(scene, RendererOptions{"threads=1", true});
    const RgbFloatImage reference = draw(reference_renderer, corner_view(1000, 256, false));
    RendererOptions traced_direct{"threads=1", true};
    traced_direct.radiance_cache.cache_direct = false;
    Renderer from_cells(scene, RendererOptions{"threads=1", true});
    Renderer traced(scene, traced_direct);
    for (std::uint64_t f = 1; f <= 16; ++f) {
        (void)draw(from_cells, corner_view(f, 1, true));
        (void)draw(traced, corner_view(f, 1, true));
    }
    const RgbFloatImage a = draw(from_cells, corner_view(17, 1, true));
    const RgbFloatImage b = draw(traced, corner_view(17, 1, true));
    std::size_t differ = 0;
    for (std::size_t i = 0; i < a.pixels.size(); i += 3) differ += a.pixels[i] != b.pixels[i] ? 1 : 0;
    EXPECT_GT(differ, a.pixels.size() / 3 / 4) << "a quarter of the pixels at least read their cell's direct light";
    const double cells_error = rel_mse(a, reference);
    const double traced_error = rel_mse(b, reference);
    EXPECT_LT(cells_error, 1.25 * traced_error)
        << "relMSE " << cells_error << " from the cells, " << traced_error << " traced at every pixel";
    EXPECT_LT(std::abs(mean(a) / mean(b) - 1.0), 0.02);
}

TEST(RendererRadianceCache, AnySplitOfACachedFrameGivesTheSameBits) {
    const Scene scene = lit_corner();
    Renderer whole(scene, RendererOptions{"threads=1", true});
    Renderer split(scene, RendererOptions{"threads=1", true});
    for (std::uint64_t f = 1; f <= 4; ++f) {
        const ViewRequest r = corner_view(f, 1, true);
        const RgbFloatImage a = draw(whole, r);
        split.begin_frame(r);
        RgbFloatImage b(split.render_size());
        const int w = b.size.width;
        const int h = b.size.height;
        // Rects in an order unlike the whole frame's, with edges off the 4x4 packet grid.
        for (const PixelRect& rect :
             {PixelRect{w / 2 + 1, h / 3, w, h}, PixelRect{0, h / 3, w / 2 + 1, h}, PixelRect{0, 0, w, h / 3}}) {
            (void)split.render(rect, b);
        }
        ASSERT_EQ(a.pixels, b.pixels) << "frame " << f;
    }
}

// A sparse cached frame (ViewRequest::shading_one_in): each pixel is the full frame's, bit for bit,
// or marked unshaded; about one surface pixel in N plus the training pixels is shaded, every pixel
// of the pattern among them; the guides are the full frame's everywhere, and it traces fewer rays.
TEST(RendererRadianceCache, ASparseFrameShadesItsPatternAndTheSameBitsThere) {
    const Scene scene = lit_corner();
    for (const int phase : {0, 3}) {  // a sparse frame trains less: each phase on caches alike
        Renderer full(scene, RendererOptions{"threads=1", true});
        Renderer sparse(scene, RendererOptions{"threads=1", true});
        for (std::uint64_t f = 1; f <= 3; ++f) (void)draw(full, corner_view(f, 1, true));
        for (std::uint64_t f = 1; f <= 3; ++f) (void)draw(sparse, corner_view(f, 1, true));
        const ViewRequest whole = corner_view(4, 1, true);
        ViewRequest thin = whole;
        thin.shading_one_in = 4;
        thin.shading_phase = phase;
        const auto render = [](Renderer& r, const ViewRequest& v, GuideBuffers& guides, std::uint64_t& rays) {
            r.begin_frame(v);
            RgbFloatImage frame(r.render_size());
            guides = GuideBuffers(frame.size);
            rays = r.render(PixelRect::whole(frame.size), frame, 0, 0, guides).rays;
            return frame;
        };
        GuideBuffers full_guides, sparse_guides;
        std::uint64_t full_rays = 0, sparse_rays = 0;
        const RgbFloatImage a = render(full, whole, full_guides, full_rays);
        const RgbFloatImage b = render(sparse, thin, sparse_guides, sparse_rays);
        EXPECT_EQ(sparse_guides.depth, full_guides.depth);
        EXPECT_EQ(sparse_guides.normal, full_guides.normal);
        std::size_t surface = 0, unshaded = 0;
        for (int y = 0; y < a.size.height; ++y) {
            for (int x = 0; x < a.size.width; ++x) {
                const bool hit = full_guides.hit[full_guides.pixel(x, y)] != 0;
                surface += hit ? 1 : 0;
                if (b.at(x, y)[0] == kUnshadedRadiance) {
                    ++unshaded;
                    EXPECT_TRUE(hit) << x << ", " << y;
                    EXPECT_FALSE(shades_pixel(4, phase, x, y)) << x << ", " << y;
                    continue;
                }
                for (int c = 0; c < 3; ++c) ASSERT_EQ(b.at(x, y)[c], a.at(x, y)[c]) << x << ", " << y;
            }
        }
        // 3/4 of the surface is off the pattern, less the training pixels (1 in 16) among them.
        EXPECT_GT(unshaded, surface * 6 / 10) << "phase " << phase;
        EXPECT_LT(unshaded, surface * 3 / 4) << "phase " << phase;
        const auto camera_rays = static_cast<std::uint64_t>(a.size.pixel_count());
        EXPECT_LT(sparse_rays - camera_rays, (full_rays - camera_rays) * 6 / 10) << "phase " << phase;
    }
}

TEST(RendererRadianceCache, FramesThatDoNotAskNeitherReadNorTrainIt) {
    const Scene scene = lit_corner();
    Renderer fresh(scene, RendererOptions{"threads=1", true});
    const RgbFloatImage expected = draw(fresh, corner_view(7, 1, false));
    Renderer used(scene, RendererOptions{"threads=1", true});
    for (std::uint64_t f = 1; f <= 4; ++f) (void)draw(used, corner_view(f, 1, true));
    EXPECT_EQ(draw(used, corner_view(7, 1, false)).pixels, expected.pixels);
    const std::size_t cells = used.radiance_cache_stats().cells;  // the last cached frame's, committed
    EXPECT_GT(cells, 0u);
    (void)draw(used, corner_view(8, 1, false));  // commits whatever the uncached frame queued: nothing
    EXPECT_EQ(used.radiance_cache_stats().cells, cells);
    used.clear_radiance_cache();
    EXPECT_EQ(used.radiance_cache_stats().cells, 0u);
}

// An animated light (scene.h, LightAnimation): the cache learnt under the old lights is emptied when
// a frame's scene time brings a change, kept while the lights stay the same, and frames under the
// new lights converge to the new reference, not the old one.
TEST(RendererRadianceCache, ALightThatChangesEmptiesTheCacheAndFramesFollowTheNewLight) {
    Scene scene = lit_corner();
    // At 1 s the main light goes out and the other one dims.
    scene.animated_lights = {{LightKind::point, 0, LightAnimation{1.0, {1.f, 0.f}}},
                             {LightKind::point, 1, LightAnimation{1.0, {1.f, 0.5f}}}};
    const auto at = [](std::uint64_t frame_id, int spp, bool cached, double time_s) {
        ViewRequest r = corner_view(frame_id, spp, cached);
        r.scene_time_s = time_s;
        return r;
    };
    Renderer reference_renderer(scene, RendererOptions{"threads=1", true});
    const RgbFloatImage before = draw(reference_renderer, at(1000, 256, false, 0.0));
    const RgbFloatImage after = draw(reference_renderer, at(1000, 256, false, 1.5));
    ASSERT_GT(mean(before) / mean(after), 1.25) << "the dimmed light must change the picture for this test to see it";

    Renderer renderer(scene, RendererOptions{"threads=1", true});
    for (std::uint64_t f = 1; f <= 32; ++f) (void)draw(renderer, at(f, 1, true, 0.03 * static_cast<double>(f)));
    renderer.begin_frame(at(33, 1, true, 0.99));  // same lights: the cache stays
    EXPECT_GT(renderer.radiance_cache_stats().cells, 100u);
    renderer.begin_frame(at(34, 1, true, 1.0));  // the light changed
    EXPECT_EQ(renderer.radiance_cache_stats().cells, 0u);
    for (std::uint64_t f = 35; f <= 66; ++f) (void)draw(renderer, at(f, 1, true, 1.0 + 0.01 * static_cast<double>(f)));
    const RgbFloatImage cached = draw(renderer, at(67, 1, true, 1.9));
    const double bias = mean(cached) / mean(after) - 1.0;
    EXPECT_LT(std::abs(bias), 0.05) << "the cached frame's mean is " << 100.0 * bias
                                    << " % off the reference under the new light";
    // The path tracer follows the light too: the same frame at the same time, bit for bit, on a
    // renderer that never saw the old light.
    Renderer fresh(scene, RendererOptions{"threads=1", true});
    EXPECT_EQ(draw(renderer, at(70, 1, false, 1.5)).pixels, draw(fresh, at(70, 1, false, 1.5)).pixels);
    EXPECT_THROW(renderer.begin_frame(at(71, 1, true, -1.0)), std::invalid_argument);
}

}  // namespace
}  // namespace mogao
