// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/tile_pass.h"

#include <fstream>
#include <new>
#include <random>
#include <string>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "renderfarm/scene/procedural.h"

namespace mogao {
namespace {

TEST(UnpackRects, PlacesEveryRectAndRejectsMismatchedSizes) {
    Rgb8Image frame({8, 4});
    const std::vector<PixelRect> rects{{0, 0, 4, 4}, {4, 0, 8, 2}};
    std::vector<std::uint8_t> packed(packed_size(rects));
    for (std::size_t i = 0; i < packed.size(); ++i) packed[i] = static_cast<std::uint8_t>(i % 251);
    unpack_rects(rects, packed, frame);
    EXPECT_EQ(frame.at(0, 0)[0], 0);
    EXPECT_EQ(frame.at(4, 0)[0], packed[static_cast<std::size_t>(4 * 4 * 3)]);
    EXPECT_EQ(frame.at(7, 3)[0], 0);  // not in any rect: untouched
    packed.pop_back();
    EXPECT_THROW(unpack_rects(rects, packed, frame), std::invalid_argument);
    EXPECT_THROW(unpack_rects({{4, 0, 9, 2}}, std::vector<std::uint8_t>(30), frame), std::invalid_argument);
}

Scene small_scene() {
    Scene scene;
    scene.meshes.push_back(make_uv_sphere(1.0, 32, 16));
    scene.meshes.push_back(make_ground_plane(20.0, 4));
    scene.materials.push_back(Material{"grey"});
    Instance sphere;
    sphere.mesh = 0;
    sphere.object_to_world.translation() = Eigen::Vector3d(0, 1, 0);
    scene.instances.push_back(sphere);
    Instance ground;
    ground.mesh = 1;
    scene.instances.push_back(ground);
    scene.directional_lights.push_back(DirectionalLight{});
    scene.point_lights.push_back(PointLight{Eigen::Vector3d(2, 3, 2), Rgb(5, 5, 5), true});
    scene.environment_lights.push_back(EnvironmentLight{});
    return scene;
}

TEST(TilePass, SplitRectsWithThreadsGiveTheSamePixelsAsOneRect) {
    const Scene scene = small_scene();
    Renderer renderer(scene, RendererOptions{});
    ViewRequest view;
    view.size = {96, 64};
    view.pose.eye = {0, 1.5, 5};
    view.quality.spp = 2;
    view.quality.ao_samples = 2;
    renderer.begin_frame(view);
    const TilePassResult whole = render_tile_pass(renderer, {{0, 0, 96, 64}}, 16, 1, 1.f);
    const std::vector<PixelRect> parts{{0, 0, 48, 64}, {48, 0, 96, 32}, {48, 32, 96, 64}};
    const TilePassResult split = render_tile_pass(renderer, parts, 16, 3, 1.f);
    Rgb8Image a({96, 64}), b({96, 64});
    unpack_rects({{0, 0, 96, 64}}, whole.packed_pixels, a);
    unpack_rects(parts, split.packed_pixels, b);
    EXPECT_EQ(a.pixels, b.pixels);
    EXPECT_EQ(whole.rays, split.rays);
    EXPECT_GT(whole.rays, 96u * 64u);  // camera rays plus shadow/AO rays
    // One timed tile per 16x16 cell, and only cells of the given rects.
    EXPECT_EQ(whole.tile_times.size(), 6u * 4u);
    for (const TileTime& t : split.tile_times) EXPECT_GE(t.seconds, 0.0);
    EXPECT_THROW((void)render_tile_pass(renderer, {{0, 0, 97, 64}}, 16, 1, 1.f), std::invalid_argument);
}

// With a control the calling thread only reports: the pixels are the uncontrolled pass's, and poll
// sees the progress, first at once (0 done) and last no further than the tile count.
TEST(TilePass, ControlledPassReportsProgressAndKeepsThePixels) {
    const Scene scene = small_scene();
    Renderer renderer(scene, RendererOptions{});
    ViewRequest view;
    view.size = {96, 64};
    view.pose.eye = {0, 1.5, 5};
    view.quality.spp = 2;
    renderer.begin_frame(view);
    const TilePassResult plain = render_tile_pass(renderer, {{0, 0, 96, 64}}, 16, 1, 1.f);
    std::vector<std::size_t> seen;
    std::size_t total_seen = 0;
    const TilePassControl control{[&](std::size_t done, std::size_t total) {
                                      seen.push_back(done);
                                      total_seen = total;
                                      return false;
                                  },
                                  0.001, 8};
    const TilePassResult beat = render_tile_pass(renderer, {{0, 0, 96, 64}}, 16, 2, 1.f, ToneMap::clamp,
                                                 PackedPixels::srgb8, nullptr, &control);
    EXPECT_EQ(beat.packed_pixels, plain.packed_pixels);
    EXPECT_EQ(beat.tiles_cut, 0u);
    ASSERT_FALSE(seen.empty());
    EXPECT_EQ(total_seen, 24u);
    for (std::size_t i = 1; i < seen.size(); ++i) EXPECT_GE(seen[i], seen[i - 1]);
    EXPECT_LE(seen.back(), 24u);
    const TilePassControl bad{[](std::size_t, std::size_t) { return false; }, 0.0, 8};
    EXPECT_THROW((void)render_tile_pass(renderer, {{0, 0, 96, 64}}, 16, 1, 1.f, ToneMap::clamp, PackedPixels::srgb8,
                                        nullptr, &bad),
                 std::invalid_argument);
}

// A cut renders the tiles not begun yet coarse: each block of the global grid holds its centre
// pixel's value, the one the full pass gives that pixel (the renderer's determinism), and the
// cut tiles' times are scaled to an estimate of their full cost.
TEST(TilePass, CutRendersTheRemainingTilesCoarseFromTheFullPassPixels) {
    const Scene scene = small_scene();
    Renderer renderer(scene, RendererOptions{});
    ViewRequest view;
    view.size = {96, 64};
    view.pose.eye = {0, 1.5, 5};
    view.quality.spp = 2;
    renderer.begin_frame(view);
    const std::vector<PixelRect> rect{{0, 0, 96, 64}};
    const TilePassResult full = render_tile_pass(renderer, rect, 16, 1, 1.f, ToneMap::clamp, PackedPixels::linear);
    const TilePassControl cut_now{[](std::size_t, std::size_t) { return true; }, 0.001, 8};
    const TilePassResult cut =
        render_tile_pass(renderer, rect, 16, 1, 1.f, ToneMap::clamp, PackedPixels::linear, nullptr, &cut_now);
    EXPECT_EQ(cut.tiles_cut, 24u);  // polled before the workers start: every tile coarse
    EXPECT_LT(cut.rays, full.rays / 8);
    EXPECT_EQ(cut.tile_times.size(), full.tile_times.size());
    RgbFloatImage a({96, 64}), b({96, 64});
    unpack_linear_rects(rect, full.packed_pixels, a);
    unpack_linear_rects(rect, cut.packed_pixels, b);
    int coarse_blocks = 0;
    for (int by = 0; by < 64; by += 8) {
        for (int bx = 0; bx < 96; bx += 8) {
            const float* centre = b.at(bx + 3, by + 3);
            bool flat = true;
            for (int y = by; y < by + 8; ++y)
                for (int x = bx; x < bx + 8; ++x)
                    for (int c = 0; c < 3; ++c) flat = flat && b.at(x, y)[c] == centre[c];
            if (!flat) continue;  // a tile begun before the cut
            ++coarse_blocks;
            for (int c = 0; c < 3; ++c) EXPECT_EQ(centre[c], a.at(bx + 3, by + 3)[c]) << bx << "," << by;
        }
    }
    EXPECT_EQ(coarse_blocks, 24 * 4);
    EXPECT_NE(a.pixels, b.pixels);  // the comparison can fail: coarse is not the full pass
}

// Packs `view` (begun on `renderer`) with guides, whole and split over ranks and threads, and checks
// that both composite to the same radiance and guides, that the radiance is the linear pass's, and
// that the guides are those of a guide pass of the whole frame on its own BVH. `pass`: the guide
// pass the tiles use (begun on the view), or null for the renderer's own first hits.
void expect_guided_packing_agrees(const Scene& scene, const Renderer& renderer, const ViewRequest& view,
                                  const GuidePass* pass) {
    const PixelRect all{0, 0, 96, 64};
    const std::vector<PixelRect> parts{{0, 0, 40, 64}, {40, 0, 96, 24}, {40, 24, 96, 64}};
    const TilePassResult whole =
        render_tile_pass(renderer, {all}, 16, 1, 1.f, ToneMap::clamp, PackedPixels::linear_guided, pass);
    const TilePassResult split =
        render_tile_pass(renderer, parts, 16, 3, 1.f, ToneMap::clamp, PackedPixels::linear_guided, pass);
    EXPECT_EQ(whole.packed_pixels.size(), 96u * 64u * 10u * sizeof(float));
    RgbFloatImage a({96, 64}), b({96, 64}), c({96, 64});
    GuideBuffers ga({96, 64}), gb({96, 64});
    unpack_guided_rects({all}, whole.packed_pixels, a, ga);
    unpack_guided_rects(parts, split.packed_pixels, b, gb);
    EXPECT_EQ(a.pixels, b.pixels);
    EXPECT_EQ(ga.hit, gb.hit);
    EXPECT_EQ(ga.albedo, gb.albedo);
    EXPECT_EQ(ga.normal, gb.normal);
    EXPECT_EQ(ga.depth, gb.depth);
    const TilePassResult linear = render_tile_pass(renderer, {all}, 16, 1, 1.f, ToneMap::clamp, PackedPixels::linear);
    unpack_linear_rects({all}, linear.packed_pixels, c);
    EXPECT_EQ(a.pixels, c.pixels) << "the radiance is the linear pass's";
    GuidePass own(scene);
    Result<GuideBuffers> expected = own.render_frame(view);
    ASSERT_TRUE(expected.ok()) << expected.error().message;
    EXPECT_EQ(ga.hit, expected->hit);
    int hits = 0;
    for (std::size_t i = 0; i < ga.depth.size(); ++i) {
        hits += ga.hit[i];
        EXPECT_NEAR(ga.depth[i], expected->depth[i], 1e-4f * (1.0f + expected->depth[i])) << i;
        for (std::size_t k = 0; k < 3; ++k) {
            EXPECT_NEAR(ga.normal[3 * i + k], expected->normal[3 * i + k], 1e-4f) << i;
            EXPECT_NEAR(ga.albedo[3 * i + k], expected->albedo[3 * i + k], 1e-6f) << i;
        }
    }
    EXPECT_GT(hits, 0);
    EXPECT_LT(hits, 96 * 64);  // sky too
}

ViewRequest guided_view() {
    ViewRequest view;
    view.size = {96, 64};
    view.pose.eye = {0, 1.5, 5};
    view.quality.max_bounces = 1;
    return view;
}

// The denoiser's guides travel beside the radiance, traced by a guide pass that shares the
// renderer's BVH (the baseline): pixel centres, a second primary ray each.
TEST(TilePass, GuidedPackingOfAnySplitEqualsTheGuidePassOfTheWholeFrame) {
    const Scene scene = small_scene();
    Renderer renderer(scene, RendererOptions{});
    GuidePass shared(scene, renderer.render_scene());
    const ViewRequest view = guided_view();
    renderer.begin_frame(view);
    ASSERT_TRUE(shared.begin_frame(view).ok());
    expect_guided_packing_agrees(scene, renderer, view, &shared);
}

// Without a guide pass the guides are the renderer's own first hits, from the rays the radiance
// traces anyway; with the pixel-centre sample (jitter off) they are the guide pass's.
TEST(TilePass, GuidedPackingWithoutAGuidePassCarriesTheRenderersFirstHits) {
    const Scene scene = small_scene();
    RendererOptions centres;
    centres.jitter_one_spp = false;
    Renderer renderer(scene, centres);
    const ViewRequest view = guided_view();
    renderer.begin_frame(view);
    expect_guided_packing_agrees(scene, renderer, view, nullptr);
}

// A moving frame from the radiance cache at 1 spp samples pixel centres with the default options,
// so the renderer's own first hits are its guides (the farm then traces no guide pass for it); any
// other 1-spp frame stays jittered, and jitter_cached_one_spp jitters the cached one too.
TEST(TilePass, ACachedOneSppFrameSamplesPixelCentresAndCarriesItsOwnGuides) {
    const Scene scene = small_scene();
    Renderer renderer(scene, RendererOptions{});
    ViewRequest view = guided_view();
    renderer.begin_frame(view);
    EXPECT_FALSE(renderer.samples_pixel_centres()) << "a path-traced 1-spp frame is jittered";
    view.radiance_cache = true;
    renderer.begin_frame(view);
    EXPECT_TRUE(renderer.samples_pixel_centres());
    expect_guided_packing_agrees(scene, renderer, view, nullptr);
    view.quality.spp = 2;
    renderer.begin_frame(view);
    EXPECT_FALSE(renderer.samples_pixel_centres()) << "two samples are a pixel's Sobol' points";
    RendererOptions jittered;
    jittered.jitter_cached_one_spp = true;
    renderer.set_path_options(jittered);
    view.quality.spp = 1;
    renderer.begin_frame(view);
    EXPECT_FALSE(renderer.samples_pixel_centres());
}

TEST(TilePass, GuidedPackingReportsTheGuidePassErrorAndRefusesMismatchedBuffers) {
    const Scene scene = small_scene();
    Renderer renderer(scene, RendererOptions{});
    ViewRequest view;
    view.size = {32, 16};
    renderer.begin_frame(view);
    GuidePass guides(scene, renderer.render_scene());  // never begun: the tile pass reports its error
    EXPECT_THROW((void)render_tile_pass(renderer, {{0, 0, 32, 16}}, 16, 1, 1.f, ToneMap::clamp,
                                        PackedPixels::linear_guided, &guides),
                 std::runtime_error);
    RgbFloatImage frame({32, 16});
    GuideBuffers ok({32, 16}), wrong({16, 16});
    std::vector<std::uint8_t> packed(packed_size({{0, 0, 32, 16}}, PackedPixels::linear_guided));
    EXPECT_NO_THROW(unpack_guided_rects({{0, 0, 32, 16}}, packed, frame, ok));
    EXPECT_THROW(unpack_guided_rects({{0, 0, 32, 16}}, packed, frame, wrong), std::invalid_argument);
    packed.pop_back();
    EXPECT_THROW(unpack_guided_rects({{0, 0, 32, 16}}, packed, frame, ok), std::invalid_argument);
    EXPECT_THROW(unpack_guided_rects({{0, 0, 33, 16}}, std::vector<std::uint8_t>(33 * 16 * 40), frame, ok),
                 std::invalid_argument);
}

// Kilobytes of this process's data segment (VmData: heap and private mappings), what RLIMIT_DATA
// bounds (Linux >= 4.7 counts mmap'ed private memory too).
long vm_data_kib() {
    std::ifstream status("/proc/self/status");
    for (std::string line; std::getline(status, line);)
        if (line.rfind("VmData:", 0) == 0) return std::stol(line.substr(7));
    return -1;
}

// A rank holds only its share of a frame: one 32x32 rect of a 16384x16384 request (the largest the
// request limits allow; a whole-frame float film would be 3 GiB) renders in a child process whose
// data segment may grow by 256 MiB at most. Before tile_pass rendered into tile-sized windows,
// each rank allocated the whole frame's film and display buffer, and this child failed.
TEST(TilePass, ARankAllocatesOnlyItsShareOfAHugeFrame) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
    GTEST_SKIP() << "a sanitizer's shadow memory counts against RLIMIT_DATA (not run in the CI suite)";
#endif
    const Scene scene = small_scene();
    Renderer renderer(scene, RendererOptions{});
    ViewRequest view;
    view.size = {16384, 16384};
    view.pose.eye = {0, 1.5, 5};
    renderer.begin_frame(view);
    const long before = vm_data_kib();
    ASSERT_GT(before, 0) << "no VmData in /proc/self/status";
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        const rlim_t limit = static_cast<rlim_t>(before + 256 * 1024) * 1024;
        const rlimit data{limit, limit};
        if (::setrlimit(RLIMIT_DATA, &data) != 0) ::_exit(3);
        try {
            const TilePassResult r = render_tile_pass(renderer, {{8192, 8192, 8224, 8224}}, 32, 1, 1.f);
            ::_exit(r.packed_pixels.size() == 32u * 32u * 3u ? 0 : 2);
        } catch (const std::bad_alloc&) {
            ::_exit(1);
        }
    }
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status)) << "the child died of signal " << WTERMSIG(status);
    EXPECT_EQ(WEXITSTATUS(status), 0)
        << "1: out of memory under a 256 MiB data limit, 2: wrong byte count, 3: setrlimit";
}

}  // namespace
}  // namespace mogao
