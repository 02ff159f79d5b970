// SPDX-License-Identifier: Apache-2.0
// Live frame scheduling on a real renderer (one process, no MPI): progressive refinement converges
// toward a converged reference and resets on motion; per-session cost-map streams.
#include "renderfarm/farm/live_frames.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <thread>

#include <gtest/gtest.h>

#include "common/image_compare.h"
#include "renderfarm/farm/tile_pass.h"
#include "renderfarm/trace/test_scenes.h"

namespace mogao {
namespace {

Scene lit_scene() {
    Scene scene = test::make_sphere_over_floor();
    AreaLight light;
    light.corner = {-0.5, 3.0, -0.5};  // emits down (edge_u x edge_v = -y)
    scene.area_lights.push_back(light);
    scene.environment_lights.push_back(EnvironmentLight{});
    return scene;
}

// The least gain of the denoised 1-spp frame over the raw one against the reference (dB); measured
// 12.3 dB on this scene when written (raw 23.2 dB, denoised 35.5 dB; the test prints both).
constexpr double kDenoiseGainDb = 6.0;

class LiveFramesTest : public ::testing::Test {
protected:
    LiveFramesTest() : scene_(lit_scene()), renderer_(scene_), guides_(scene_, renderer_.render_scene()) {}

    // The stand-in for the FrameDispatcher: the whole frame on this thread, and a record of the calls.
    FrameSource source() {
        return [this](const ViewRequest& view, std::uint64_t stream, PackedPixels format) {
            const auto start = std::chrono::steady_clock::now();
            calls_.push_back({view, stream, format});
            renderer_.begin_frame(view);
            if (format == PackedPixels::linear_guided) {
                EXPECT_TRUE(guides_.begin_frame(view).ok());
            }
            TilePassResult pass = render_tile_pass(renderer_, {PixelRect::whole(renderer_.render_size())}, 16, 2, 1.f,
                                                   ToneMap::clamp, format, &guides_);
            DispatchedFrame frame;
            if (format == PackedPixels::linear_guided) {
                frame.radiance = RgbFloatImage(renderer_.render_size());
                frame.guides = GuideBuffers(frame.radiance.size);
                unpack_guided_rects({PixelRect::whole(frame.radiance.size)}, pass.packed_pixels, frame.radiance,
                                    frame.guides);
            } else if (format == PackedPixels::linear) {
                frame.radiance = RgbFloatImage(renderer_.render_size());
                unpack_linear_rects({PixelRect::whole(frame.radiance.size)}, pass.packed_pixels, frame.radiance);
            } else {
                frame.image = Rgb8Image(renderer_.render_size());
                unpack_rects({PixelRect::whole(frame.image.size)}, pass.packed_pixels, frame.image);
            }
            calls_.back().seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            return frame;
        };
    }

    [[nodiscard]] ViewRequest view(double yaw = 0.0) const {
        ViewRequest v = test::look_at({0.0, 1.5, 3.0}, {0.0, 0.8, 0.0}, {64, 48}, 50.0);
        v.pose.yaw_deg += yaw;
        v.quality.area_light_samples = 1;
        v.session = 7;
        return v;
    }

    // A single render at `spp` (the converged reference at high spp), sRGB8.
    Rgb8Image single(ViewRequest v, int spp, std::uint64_t frame_id = 999'999) {
        v.quality.spp = spp;
        v.frame_id = frame_id;
        renderer_.begin_frame(v);
        RgbFloatImage radiance(renderer_.render_size());
        (void)renderer_.render(PixelRect::whole(radiance.size), radiance);
        Rgb8Image out(radiance.size);
        to_srgb8(radiance, PixelRect::whole(radiance.size), 1.f, out);
        return out;
    }

    struct Call {
        ViewRequest view;
        std::uint64_t stream;
        PackedPixels format;
        double seconds = 0.0;  // wall time of the stand-in's render
    };
    Scene scene_;
    Renderer renderer_;
    GuidePass guides_;
    std::vector<Call> calls_;
};

TEST_F(LiveFramesTest, StillViewConvergesTowardTheReferenceWithNewSamplesEachPass) {
    LiveFrames live(source(), {}, 1.f, ToneMap::clamp);
    const Rgb8Image reference = single(view(), 1024);  // converged
    std::vector<double> psnr_after;                    // after 1, 4, 16, 64 passes
    ViewRequest request = view();
    for (int pass = 1; pass <= 64; ++pass) {
        request.frame_id = static_cast<std::uint64_t>(pass);
        const LiveFrame frame = live.render(request);
        ASSERT_EQ(frame.passes, pass);
        if (pass == 1 || pass == 4 || pass == 16 || pass == 64) psnr_after.push_back(psnr(frame.image, reference));
    }
    // 1 + 63 x 2 samples: the first pass at the request's 1 spp, later ones at least 2 (jittered).
    EXPECT_EQ(live.render(request).samples, 1 + 64 * 2);
    for (std::size_t i = 1; i < psnr_after.size(); ++i)
        EXPECT_GT(psnr_after[i], psnr_after[i - 1] + 1.0) << "after pass index " << i;
    // Every pass drew new random numbers: no two passes share a frame_id (the RNG key).
    std::set<std::uint64_t> ids;
    for (const Call& c : calls_) ids.insert(c.view.frame_id);
    EXPECT_EQ(ids.size(), calls_.size());
    EXPECT_EQ(calls_.front().view.frame_id, 1u);  // pass 0 renders as the request asked
    // Passes are independent estimates: 4x the samples divides the squared error by about 4 (+6 dB)
    // while the reference's own noise and 8-bit rounding are far below it. (A single render with as
    // many samples is better still: its samples form one stratified Sobol' net per pixel.)
    const double gain = psnr_after[3] - psnr_after[2];
    EXPECT_GT(gain, 4.0);
    EXPECT_LT(gain, 8.0);
    std::printf("PSNR after 1, 4, 16, 64 passes: %.2f %.2f %.2f %.2f dB; one render at 127 spp: %.2f dB\n",
                psnr_after[0], psnr_after[1], psnr_after[2], psnr_after[3], psnr(single(view(), 127), reference));
}

// A visitor who stops: the first request at the pose is a moving frame (from the radiance cache,
// never accumulated), the repeat starts the still view's accumulation with still_first_pass_spp
// samples, the next pass adds still_second_pass_spp.
TEST_F(LiveFramesTest, AStillViewsFirstPassTakesItsOwnSampleCount) {
    for (const int first : {1, 2, 3}) {
        LiveOptions options;
        options.radiance_cache = true;
        options.still_first_pass_spp = first;
        options.still_second_pass_spp = 2;
        LiveFrames live(source(), options, 1.f, ToneMap::clamp);
        ViewRequest request = view(10.0);
        request.frame_id = 1;
        (void)live.render(request);  // somewhere else
        request = view();
        request.frame_id = 2;
        EXPECT_EQ(live.render(request).samples, 1) << "the first frame at a new pose is a moving frame";
        request.frame_id = 3;
        const LiveFrame still = live.render(request);
        EXPECT_TRUE(still.still);
        EXPECT_EQ(still.rendered.quality.spp, first);
        EXPECT_EQ(still.samples, first);
        EXPECT_EQ(still.passes, 1);
        request.frame_id = 4;
        EXPECT_EQ(live.render(request).samples, first + 2);
    }
}

TEST_F(LiveFramesTest, AnyMotionStartsOver) {
    LiveFrames live(source(), {}, 1.f, ToneMap::clamp);
    ViewRequest request = view();
    for (std::uint64_t id = 1; id <= 5; ++id) {
        request.frame_id = id;
        (void)live.render(request);
    }
    request = view(0.5);  // half a degree of yaw
    request.frame_id = 6;
    const LiveFrame moved = live.render(request);
    EXPECT_EQ(moved.passes, 1);
    EXPECT_EQ(moved.samples, 1);
    EXPECT_EQ(calls_.back().view.frame_id, 6u);
    // The moved view's single pass is what it is: no trace of the old view's passes.
    EXPECT_EQ(max_abs_difference(moved.image, single(request, 1, 6)), 0.0);
}

TEST_F(LiveFramesTest, ConvergedStillViewIsServedWithoutRendering) {
    LiveOptions options;
    options.converged_spp = 5;  // 1 + 2 + 2
    LiveFrames live(source(), options, 1.f, ToneMap::clamp);
    ViewRequest request = view();
    for (std::uint64_t id = 1; id <= 6; ++id) {
        request.frame_id = id;
        const LiveFrame frame = live.render(request);
        EXPECT_EQ(frame.rendered_now, id <= 3) << id;
    }
    EXPECT_EQ(calls_.size(), 3u);
}

TEST_F(LiveFramesTest, WithoutProgressiveEachRequestRendersAlone) {
    LiveOptions options;
    options.progressive = false;
    LiveFrames live(source(), options, 1.f, ToneMap::clamp);
    ViewRequest request = view();
    for (std::uint64_t id = 1; id <= 3; ++id) {
        request.frame_id = id;
        const LiveFrame frame = live.render(request);
        EXPECT_EQ(frame.samples, 1);
        EXPECT_EQ(calls_.back().view.frame_id, id);
    }
}

TEST_F(LiveFramesTest, EachSessionPredictsFromItsOwnCostMap) {
    LiveOptions shared;
    shared.per_session_maps = false;
    for (const bool per_session : {true, false}) {
        calls_.clear();
        LiveFrames live(source(), per_session ? LiveOptions{} : shared, 1.f, ToneMap::clamp);
        ViewRequest a = view();
        ViewRequest b = view(30.0);
        a.session = 1;
        b.session = 2;
        a.frame_id = b.frame_id = 1;
        (void)live.render(a);
        (void)live.render(b);
        ASSERT_EQ(calls_.size(), 2u);
        EXPECT_EQ(calls_[0].stream, per_session ? 1u : 0u);
        EXPECT_EQ(calls_[1].stream, per_session ? 2u : 0u);
    }
}

TEST_F(LiveFramesTest, SessionsAccumulateIndependently) {
    LiveFrames live(source(), {}, 1.f, ToneMap::clamp);
    ViewRequest a = view();
    ViewRequest b = view(30.0);
    a.session = 1;
    b.session = 2;
    for (std::uint64_t id = 1; id <= 3; ++id) {
        a.frame_id = b.frame_id = id;
        EXPECT_EQ(live.render(a).passes, static_cast<int>(id));
        EXPECT_EQ(live.render(b).passes, static_cast<int>(id));  // b does not reset a, nor a b
    }
}

TEST_F(LiveFramesTest, FrameTimeTargetPicksTheScaleOfMovingViewsAndFullScaleWhenStill) {
    LiveOptions options;
    options.frame_time_s = 1e-9;  // unreachable: every moving frame falls to the smallest scale
    options.controller.min_scale = 0.5;
    options.controller.min_bounces = 0;
    LiveFrames live(source(), options, 1.f, ToneMap::clamp);
    for (std::uint64_t id = 1; id <= 8; ++id) {
        ViewRequest moving = view(static_cast<double>(id));
        moving.quality.max_bounces = 2;
        moving.frame_id = id;
        (void)live.render(moving);
    }
    // The scale holds its floor; below it the bounces went instead.
    EXPECT_DOUBLE_EQ(calls_.back().view.quality.resolution_scale, 0.5);
    EXPECT_EQ(calls_.back().view.quality.max_bounces, 0);
    ViewRequest still = view(8.0);
    still.quality.max_bounces = 2;
    still.frame_id = 9;
    const LiveFrame frame = live.render(still);
    EXPECT_DOUBLE_EQ(frame.rendered.quality.resolution_scale, 1.0);
    EXPECT_EQ(frame.rendered.quality.max_bounces, 2);  // a still view accumulates at its own depth
    EXPECT_EQ(frame.image.size, (ImageSize{64, 48}));
}

// ---- the denoiser on served frames -------------------------------------------------------------

// A moving view with one bounce at 1 spp: the served frame, denoised by the farm, against a
// reference of many samples rendered alone (not the system's own prediction).
TEST_F(LiveFramesTest, DenoisedMovingFrameIsCloserToAManySppReferenceThanTheRawOne) {
    ViewRequest request = view(3.0);
    request.size = {96, 72};
    request.quality.max_bounces = 1;
    request.frame_id = 11;
    const Rgb8Image reference = single(request, 256);
    LiveOptions raw_options;
    raw_options.progressive = false;
    LiveOptions denoised_options = raw_options;
    denoised_options.denoise = true;
    LiveFrames raw(source(), raw_options, 1.f, ToneMap::clamp);
    LiveFrames denoised(source(), denoised_options, 1.f, ToneMap::clamp);
    const LiveFrame a = raw.render(request);
    const LiveFrame b = denoised.render(request);  // the same samples (same frame_id), filtered
    EXPECT_FALSE(a.denoised);
    EXPECT_TRUE(b.denoised);
    EXPECT_EQ(calls_.back().format, PackedPixels::linear_guided);
    const double raw_db = psnr(a.image, reference), denoised_db = psnr(b.image, reference);
    std::printf("moving frame, 1 spp, 1 bounce: raw %.2f dB, denoised %.2f dB against 256 spp\n", raw_db, denoised_db);
    EXPECT_GT(denoised_db, raw_db + kDenoiseGainDb);
}

// A moving view with temporal accumulation: each filtered frame is blended with the earlier frames
// reprojected to it, so the last of a turn is closer to the reference than the filter alone makes
// it; a still view's frames, its first pass included, are not blended (unbiased at full scale).
TEST_F(LiveFramesTest, TemporalAccumulationBringsAMovingFrameCloserToTheReference) {
    ViewRequest request = view(0.0);
    request.size = {96, 72};
    request.quality.max_bounces = 1;
    const Rgb8Image reference = single(request, 256);
    LiveOptions filtered_options;
    filtered_options.denoise = true;
    LiveOptions temporal_options = filtered_options;
    temporal_options.temporal = true;
    LiveFrames filtered(source(), filtered_options, 1.f, ToneMap::clamp);
    LiveFrames temporal(source(), temporal_options, 1.f, ToneMap::clamp);
    LiveFrame a;
    LiveFrame b;
    for (int k = 8; k >= 0; --k) {  // turning towards the reference's pose, a degree a frame
        ViewRequest r = request;
        r.pose.yaw_deg += k;
        r.frame_id = 100 + static_cast<std::uint64_t>(8 - k);
        a = filtered.render(r);
        b = temporal.render(r);
    }
    const double filtered_db = psnr(a.image, reference), temporal_db = psnr(b.image, reference);
    std::printf("moving frame after 9 frames, 1 spp: filtered %.2f dB, temporal + filtered %.2f dB\n", filtered_db,
                temporal_db);
    EXPECT_GT(temporal_db, filtered_db + 1.0);
    // A degree's turn: nearly every surface pixel was seen by the previous frame (the scene is static).
    EXPECT_GT(b.temporal.surface_pixels, 0u);
    EXPECT_GT(b.temporal.reprojected, b.temporal.surface_pixels * 8 / 10)
        << b.temporal.reprojected << " of " << b.temporal.surface_pixels << " surface pixels reprojected";
    EXPECT_LE(b.temporal.reprojected, b.temporal.surface_pixels);
    EXPECT_EQ(a.temporal.surface_pixels, 0u) << "the filter alone blends nothing";

    ViewRequest still = request;
    still.frame_id = 200;
    (void)filtered.render(still);
    (void)temporal.render(still);  // the still view's second pass: accumulated, not blended
    still.frame_id = 201;
    EXPECT_EQ(filtered.render(still).image.pixels, temporal.render(still).image.pixels);

    // Moving frames from the radiance cache are not accumulated, so the still view's first pass
    // follows a moving history of cached frames: it is not blended with them either.
    filtered_options.radiance_cache = temporal_options.radiance_cache = true;
    LiveFrames cached(source(), filtered_options, 1.f, ToneMap::clamp);
    LiveFrames cached_temporal(source(), temporal_options, 1.f, ToneMap::clamp);
    for (int k = 3; k >= 0; --k) {
        ViewRequest r = request;
        r.pose.yaw_deg += k;
        r.frame_id = 300 + static_cast<std::uint64_t>(3 - k);
        renderer_.clear_radiance_cache();
        (void)cached.render(r);
        renderer_.clear_radiance_cache();
        (void)cached_temporal.render(r);
    }
    still.frame_id = 400;
    const LiveFrame first = cached.render(still);
    ASSERT_EQ(first.passes, 1);
    ASSERT_TRUE(first.still);
    EXPECT_EQ(first.image.pixels, cached_temporal.render(still).image.pixels)
        << "a still view's first pass is not blended with the moving history";
}

// A moving frame blended with its history is filtered with blended_denoise_iterations levels, every other
// filtered frame (a still view's) with denoise_params.iterations.
TEST_F(LiveFramesTest, ABlendedFrameIsFilteredWithItsOwnLevelsAndAStillViewWithTheFilters) {
    ViewRequest request = view(0.0);
    request.size = {96, 72};
    LiveOptions unfiltered_blend;  // still views filtered with the default levels, blended frames not at all
    unfiltered_blend.denoise = unfiltered_blend.temporal = true;
    unfiltered_blend.blended_denoise_iterations = 0;
    LiveOptions never_filtered = unfiltered_blend;
    never_filtered.denoise_params.iterations = 0;
    LiveOptions filtered_blend = unfiltered_blend;
    filtered_blend.blended_denoise_iterations = 2;
    LiveFrames a(source(), unfiltered_blend, 1.f, ToneMap::clamp);
    LiveFrames b(source(), never_filtered, 1.f, ToneMap::clamp);
    LiveFrames c(source(), filtered_blend, 1.f, ToneMap::clamp);
    for (int k = 3; k >= 1; --k) {
        ViewRequest r = request;
        r.pose.yaw_deg += k;
        r.frame_id = 500 + static_cast<std::uint64_t>(3 - k);
        const LiveFrame fa = a.render(r), fb = b.render(r), fc = c.render(r);
        ASSERT_TRUE(fa.denoised);
        EXPECT_EQ(fa.image.pixels, fb.image.pixels) << "frame " << k << ": blended, filtered with its own levels";
        EXPECT_NE(fa.image.pixels, fc.image.pixels) << "frame " << k;
    }
    ViewRequest still = request;
    still.pose.yaw_deg += 1;  // the last moving view again: a still view's first pass
    still.frame_id = 600;
    const LiveFrame sa = a.render(still), sb = b.render(still);
    ASSERT_TRUE(sa.still);
    EXPECT_NE(sa.image.pixels, sb.image.pixels) << "a still view is filtered with denoise_params' levels";
}

// A blended frame's filter takes the history's temporal luminance variance (temporal_variance) once a
// pixel's history holds four frames: before that, every pixel gets the spatial estimate, so the
// frames are those of temporal_variance off bit for bit; after it they differ.
TEST_F(LiveFramesTest, ABlendedFrameTakesTheTemporalVarianceOnceTheHistoryIsLongEnough) {
    ViewRequest request = view(0.0);
    request.size = {96, 72};
    LiveOptions temporal_variance;
    temporal_variance.denoise = temporal_variance.temporal = true;
    LiveOptions spatial_variance = temporal_variance;
    spatial_variance.temporal_variance = false;
    ASSERT_TRUE(temporal_variance.temporal_variance) << "the default";
    LiveFrames a(source(), temporal_variance, 1.f, ToneMap::clamp);
    LiveFrames b(source(), spatial_variance, 1.f, ToneMap::clamp);
    for (int k = 1; k <= 5; ++k) {
        ViewRequest r = request;
        r.pose.yaw_deg += 0.1 * k;
        r.frame_id = 700 + static_cast<std::uint64_t>(k);
        const LiveFrame fa = a.render(r), fb = b.render(r);
        ASSERT_TRUE(fa.denoised && fb.denoised);
        ASSERT_FALSE(fa.still);
        if (k < 4) {
            EXPECT_EQ(fa.image.pixels, fb.image.pixels) << "frame " << k << ": no pixel has four frames yet";
        } else {
            EXPECT_NE(fa.image.pixels, fb.image.pixels) << "frame " << k;
        }
    }
}

double mean_of(const Rgb8Image& image) {
    double sum = 0.0;
    for (const std::uint8_t v : image.pixels) sum += v;
    return sum / static_cast<double>(image.pixels.size());
}

// An animated light (scene.h): each request is stamped with the scene time; when the light changes,
// the still view's accumulation starts again (it would otherwise average both lights) and the moving
// frames' temporal history is dropped (it would otherwise carry the old light into the new frames).
TEST_F(LiveFramesTest, ALightThatChangesRestartsTheStillViewAndDropsTheTemporalHistory) {
    scene_.animated_lights = {{LightKind::area, 0, LightAnimation{1.0, {1.f, 0.f}}}};  // off at 1 s
    double clock = 0.0;
    LiveOptions options;
    options.lighting = [this](double t) { return lighting_state(scene_, t); };
    options.scene_clock = [&clock] { return clock; };
    LiveFrames live(source(), options, 1.f, ToneMap::clamp);
    ViewRequest still = view();
    LiveFrame frame;
    for (int pass = 1; pass <= 4; ++pass) {
        clock = 0.2 * pass;
        still.frame_id = static_cast<std::uint64_t>(pass);
        frame = live.render(still);
        ASSERT_EQ(frame.passes, pass);
    }
    const double lit = mean_of(frame.image);
    ViewRequest unlit_view = still;
    unlit_view.scene_time_s = 1.1;
    const double unlit = mean_of(single(unlit_view, 16));  // sRGB8 means, the sky alone
    ASSERT_GT(lit, unlit + 5.0) << "the light must change the picture for this test to see it";
    clock = 1.1;
    still.frame_id = 5;
    frame = live.render(still);
    EXPECT_EQ(frame.passes, 1) << "the still view's samples under the old light were kept";
    EXPECT_DOUBLE_EQ(calls_.back().view.scene_time_s, 1.1);
    EXPECT_NEAR(mean_of(frame.image), unlit, 2.0) << "lit " << lit;

    // Moving frames, temporal accumulation on: the first frame after the change equals a frame of a
    // session that never saw the old light (its history is empty too).
    options.denoise = options.temporal = true;
    LiveFrames temporal(source(), options, 1.f, ToneMap::clamp);
    LiveFrames fresh(source(), options, 1.f, ToneMap::clamp);
    for (int k = 6; k >= 1; --k) {
        clock = 0.1 * (7 - k);
        ViewRequest r = view(k);
        r.frame_id = 100 + static_cast<std::uint64_t>(k);
        (void)temporal.render(r);
    }
    clock = 1.5;
    ViewRequest r = view(0.0);
    r.frame_id = 200;
    const LiveFrame after = temporal.render(r);
    const LiveFrame alone = fresh.render(r);
    EXPECT_EQ(after.image.pixels, alone.image.pixels) << "the old light's history was blended in";
}

// Cached moving frames with a history shade one pixel in shading_one_in, the pattern moving on a
// phase each frame; the first frame of a session (no history), a still view's passes, sessions
// without temporal accumulation and frames the filter does not take shade every pixel. The served frames stay close to
// those of a session that shades every pixel (no unshaded pixel shows).
TEST_F(LiveFramesTest, CachedMovingFramesShadeOnePixelInNOnAMovingPattern) {
    LiveOptions options;
    options.radiance_cache = options.denoise = options.temporal = true;
    LiveOptions every_pixel = options;
    every_pixel.shading_one_in = 1;
    LiveFrames sparse(source(), options, 1.f, ToneMap::clamp);
    LiveFrames full(source(), every_pixel, 1.f, ToneMap::clamp);
    std::vector<int> one_in, phase;
    LiveFrame a, b;
    for (std::uint64_t k = 0; k < 6; ++k) {
        ViewRequest r = view(0.5 * static_cast<double>(k));
        r.frame_id = 10 + k;
        a = sparse.render(r);
        one_in.push_back(calls_.back().view.shading_one_in);
        phase.push_back(calls_.back().view.shading_phase);
        b = full.render(r);
        EXPECT_EQ(calls_.back().view.shading_one_in, 1);
    }
    EXPECT_EQ(one_in, (std::vector<int>{1, 4, 4, 4, 4, 4}));
    EXPECT_EQ(phase, (std::vector<int>{0, 0, 1, 2, 3, 0}));
    EXPECT_GT(a.temporal.unshaded, a.temporal.surface_pixels / 2);
    EXPECT_GT(psnr(a.image, b.image), 30.0) << "the sparse session's frame against the full one's";
    EXPECT_NEAR(mean_of(a.image), mean_of(b.image), 1.0);

    ViewRequest still = view(2.5);  // the last view again: a still view's first pass, uncached
    still.frame_id = 20;
    (void)sparse.render(still);
    EXPECT_EQ(calls_.back().view.shading_one_in, 1);
    options.temporal = false;
    LiveFrames no_history(source(), options, 1.f, ToneMap::clamp);
    for (std::uint64_t k = 0; k < 3; ++k) {
        ViewRequest r = view(0.5 * static_cast<double>(k));
        r.frame_id = 30 + k;
        (void)no_history.render(r);
        EXPECT_EQ(calls_.back().view.shading_one_in, 1);
    }
    // Frames of more samples than the filter takes are shown as traced, never blended: never sparse.
    options.temporal = true;
    options.denoise_max_spp = 1;
    LiveFrames unfiltered(source(), options, 1.f, ToneMap::clamp);
    for (std::uint64_t k = 0; k < 4; ++k) {  // two filtered frames make a history, then two that are not
        ViewRequest r = view(0.5 * static_cast<double>(k));
        r.frame_id = 40 + k;
        r.quality.spp = k < 2 ? 1 : 2;
        (void)unfiltered.render(r);
        EXPECT_EQ(calls_.back().view.shading_one_in, k == 1 ? 4 : 1) << "frame " << k;
    }
}

// A still view: the guides are traced with its first pass only, and frames are filtered while they
// hold at most denoise_max_spp samples (1, then 1 + 2), raw after that (1 + 2 + 2 = 5).
TEST_F(LiveFramesTest, StillViewIsDenoisedUpToDenoiseMaxSppWithTheFirstPassesGuides) {
    LiveOptions options;
    options.denoise = true;
    options.denoise_max_spp = 4;
    LiveFrames live(source(), options, 1.f, ToneMap::clamp);
    ViewRequest request = view();
    const bool expected[] = {true, true, false, false};
    for (std::uint64_t id = 1; id <= 4; ++id) {
        request.frame_id = id;
        const LiveFrame frame = live.render(request);
        EXPECT_EQ(frame.denoised, expected[id - 1]) << "pass " << id << ", " << frame.samples << " spp";
        EXPECT_EQ(calls_.back().format, id == 1 ? PackedPixels::linear_guided : PackedPixels::linear) << id;
    }
    // Motion: a new view, new guides.
    ViewRequest moved = view(1.0);
    moved.frame_id = 5;
    EXPECT_TRUE(live.render(moved).denoised);
    EXPECT_EQ(calls_.back().format, PackedPixels::linear_guided);
}

// A still view refining past its first passes: filtered with the noise its passes measure, each
// frame is closer to the reference than the one before and than the raw mean of the same samples
// (the raw frame is what a view past denoise_max_spp showed: noisier than its own first passes).
TEST_F(LiveFramesTest, StillViewKeepsImprovingWithTheNoiseItsPassesMeasure) {
    ViewRequest request = view(2.0);
    request.size = {96, 72};
    request.quality.max_bounces = 1;
    const Rgb8Image reference = single(request, 512);
    LiveOptions filtered_options;
    filtered_options.denoise = true;
    LiveOptions raw_options = filtered_options;
    raw_options.denoise_max_spp = 1;  // the first pass filtered, the accumulation raw
    LiveFrames filtered(source(), filtered_options, 1.f, ToneMap::clamp);
    LiveFrames raw(source(), raw_options, 1.f, ToneMap::clamp);
    double previous_db = 0.0;
    for (std::uint64_t id = 1; id <= 7; ++id) {
        request.frame_id = id;
        const LiveFrame a = filtered.render(request);
        const LiveFrame b = raw.render(request);
        ASSERT_EQ(a.samples, b.samples);
        const double filtered_db = psnr(a.image, reference), raw_db = psnr(b.image, reference);
        std::printf("still view, %2d spp: filtered with the measured noise %.2f dB, raw %.2f dB\n", a.samples,
                    filtered_db, raw_db);
        EXPECT_TRUE(a.denoised);
        if (id == 1) continue;
        EXPECT_GT(filtered_db, previous_db - 0.1) << a.samples << " spp: worse than the frame before";
        EXPECT_GT(filtered_db, raw_db + 2.0) << a.samples << " spp";
        previous_db = filtered_db;
    }
}

// The frame-time target sees the filter's time: a controller fed each frame's seconds (render +
// filter) and the hand-off gap before it chooses exactly the scale LiveFrames renders next, and
// those seconds hold the source's render and the filter one after the other.
TEST_F(LiveFramesTest, FrameTimeTargetIsChargedTheFilterTime) {
    LiveOptions options;
    options.denoise = true;
    options.frame_time_s = 1e-3;
    options.controller.min_scale = 0.25;
    LiveFrames live(source(), options, 1.f, ToneMap::clamp);
    FrameTimeController replica(live.options().controller);
    for (std::uint64_t id = 1; id <= 4; ++id) {
        ViewRequest moving = view(static_cast<double>(id));
        moving.frame_id = id;
        const FrameChoice expected = replica.choose(moving);
        const LiveFrame frame = live.render(moving);
        EXPECT_DOUBLE_EQ(frame.rendered.quality.resolution_scale, expected.resolution_scale) << id;
        ASSERT_TRUE(frame.denoised);
        EXPECT_GT(frame.denoise_seconds, 0.0);
        EXPECT_GE(frame.seconds, calls_.back().seconds + frame.denoise_seconds);
        replica.observe(expected, frame.seconds, frame.gap_seconds);
    }
}

// With the target shared, each of two sessions served in turn aims at half the target: a replica
// controller given target / active sessions before each choice picks exactly the scale LiveFrames
// renders, and one given the whole target (the unshared farm) picks another at least once. Frame
// times are real (about 0.6 ms a frame on a quiet 2-core machine, tens of ms on a loaded one): for
// one target both choices can sit at full scale or at the floor, so targets from 0.125 ms to 32 ms
// are tried until one tells them apart (the scales must match at every one).
int shared_target_round(LiveFrames& live, const std::function<ViewRequest(double)>& view) {
    const double target = live.options().controller.target_seconds;
    std::map<std::uint64_t, FrameTimeController> shared, whole;
    int differs = 0;
    for (std::uint64_t id = 1; id <= 6; ++id) {
        for (const std::uint64_t session : {7u, 8u}) {
            ViewRequest moving = view(static_cast<double>(id));
            moving.session = session;
            moving.frame_id = id;
            FrameTimeController& replica = shared.try_emplace(session, live.options().controller).first->second;
            FrameTimeController& alone = whole.try_emplace(session, live.options().controller).first->second;
            const int active = id == 1 && session == 7 ? 1 : 2;  // session 8 is new after 7's first frame
            replica.set_target_seconds(target / active);
            const FrameChoice expected = replica.choose(moving);
            const FrameChoice unshared = alone.choose(moving);
            const LiveFrame frame = live.render(moving);
            EXPECT_DOUBLE_EQ(frame.rendered.quality.resolution_scale, expected.resolution_scale)
                << id << " " << session;
            differs += unshared.resolution_scale != expected.resolution_scale ? 1 : 0;
            replica.observe(expected, frame.seconds, frame.gap_seconds);
            alone.observe(unshared, frame.seconds, frame.gap_seconds);
        }
    }
    return differs;
}

TEST_F(LiveFramesTest, SharedFrameTimeTargetIsDividedAmongTheActiveSessions) {
    int differs = 0;
    for (const double frame_time_s : {2e-3, 5e-4, 1.25e-4, 8e-3, 32e-3}) {
        LiveOptions options;
        options.frame_time_s = frame_time_s;
        options.share_frame_time = true;
        options.controller.min_scale = 0.1;
        LiveFrames live(source(), options, 1.f, ToneMap::clamp);
        differs = shared_target_round(live, [this](double t) { return view(t); });
        if (differs > 0) break;
    }
    EXPECT_GT(differs, 0) << "the shared target never changed a choice: the test cannot tell it from the whole target";
}

// The appliance's pace (LiveOptions::follow_request_pace, request_pace.h): requests stamped 20 ms apart, the farm
// waiting a few ms for each, move the session's target from T to its cap 2 T (0.85 x 20 ms is above it) from the
// second request on, when the period and the wait are first known; a replica controller given that target picks
// exactly LiveFrames' scales, and one given T alone picks another at least once (targets tried until one tells them
// apart, as for the shared target).
TEST_F(LiveFramesTest, AFrameTakesTheTimeTheAppliancesPaceGivesIt) {
    int differs = 0;
    for (const double frame_time_s : {1e-3, 2.5e-4, 4e-3, 0.5e-4}) {
        LiveOptions options;
        options.frame_time_s = frame_time_s;
        options.follow_request_pace = true;
        options.controller.min_scale = 0.1;
        LiveFrames live(source(), options, 1.f, ToneMap::clamp);
        FrameTimeController replica(live.options().controller);
        FrameTimeController alone(live.options().controller);
        differs = 0;
        for (std::uint64_t id = 1; id <= 8; ++id) {
            std::this_thread::sleep_for(std::chrono::milliseconds(3));
            ViewRequest moving = view(static_cast<double>(id));
            moving.frame_id = id;
            moving.request_time_ns = static_cast<std::int64_t>(id) * 20'000'000;
            replica.set_target_seconds(id >= 2 ? 2 * frame_time_s : frame_time_s);
            const FrameChoice expected = replica.choose(moving);
            const FrameChoice unpaced = alone.choose(moving);
            const LiveFrame frame = live.render(moving);
            EXPECT_DOUBLE_EQ(frame.rendered.quality.resolution_scale, expected.resolution_scale) << id;
            differs += unpaced.resolution_scale != expected.resolution_scale ? 1 : 0;
            replica.observe(expected, frame.seconds, frame.gap_seconds);
            alone.observe(unpaced, frame.seconds, frame.gap_seconds);
        }
        if (differs > 0) break;
    }
    EXPECT_GT(differs, 0) << "the paced target never changed a choice: the test cannot tell it from the target";
}

// An equal turn: a session's share of the farm is the other active session's recent frame time
// (here its one frame), never less than the target; alone, or with sharing off, there is none.
TEST_F(LiveFramesTest, FrameShareIsTheOtherSessionsRecentFrameTimeAndNoneAlone) {
    LiveOptions options;
    options.frame_time_s = 1e-7;
    options.share_frame_time = true;
    LiveFrames live(source(), options, 1.f, ToneMap::clamp);
    ViewRequest a = view(1.0);
    EXPECT_EQ(live.frame_share_seconds(7), 0.0);
    const LiveFrame first = live.render(a);
    EXPECT_EQ(live.frame_share_seconds(7), 0.0) << "alone";
    EXPECT_DOUBLE_EQ(live.frame_share_seconds(8), std::max(1e-7, first.seconds));
    ViewRequest b = view(2.0);
    b.session = 8;
    const LiveFrame second = live.render(b);
    EXPECT_DOUBLE_EQ(live.frame_share_seconds(7), std::max(1e-7, second.seconds));
    options.share_frame_time = false;
    LiveFrames unshared(source(), options, 1.f, ToneMap::clamp);
    (void)unshared.render(a);
    EXPECT_EQ(unshared.frame_share_seconds(8), 0.0);
}

// Multi-rank equals single-rank: the admin filters the composited frame, and the guided packing of
// any split of the frame composites to the same radiance and guides.
TEST_F(LiveFramesTest, DenoisedFrameIsTheSameForAnySplitOfTheFrame) {
    const FrameSource split = [this](const ViewRequest& v, std::uint64_t, PackedPixels format) {
        renderer_.begin_frame(v);
        EXPECT_TRUE(guides_.begin_frame(v).ok());
        const ImageSize size = renderer_.render_size();
        DispatchedFrame frame;
        frame.radiance = RgbFloatImage(size);
        frame.guides = GuideBuffers(size);
        // Two "ranks": the left third and the rest, in rects the PBT could give.
        const std::vector<std::vector<PixelRect>> ranks{{{0, 0, size.width / 3, size.height}},
                                                        {{size.width / 3, 0, size.width, size.height / 2},
                                                         {size.width / 3, size.height / 2, size.width, size.height}}};
        for (const auto& rects : ranks) {
            const TilePassResult pass =
                render_tile_pass(renderer_, rects, 16, 1, 1.f, ToneMap::clamp, format, &guides_);
            unpack_guided_rects(rects, pass.packed_pixels, frame.radiance, frame.guides);
        }
        return frame;
    };
    LiveOptions options;
    options.denoise = true;
    ViewRequest request = view(2.0);
    request.quality.max_bounces = 1;
    request.frame_id = 3;
    LiveFrames whole(source(), options, 1.f, ToneMap::clamp);
    LiveFrames parts(split, options, 1.f, ToneMap::clamp);
    const LiveFrame a = whole.render(request);
    const LiveFrame b = parts.render(request);
    ASSERT_TRUE(a.denoised && b.denoised);
    EXPECT_EQ(max_abs_difference(a.image, b.image), 0.0);
}

TEST_F(LiveFramesTest, DenoiserRefusesGuidesThatDoNotFitTheFrame) {
    LiveOptions options;
    options.denoise = true;
    options.progressive = false;
    const FrameSource no_guides = [this](const ViewRequest& v, std::uint64_t s, PackedPixels f) {
        DispatchedFrame frame = source()(v, s, f);
        frame.guides = GuideBuffers({2, 2});
        return frame;
    };
    LiveFrames live(no_guides, options, 1.f, ToneMap::clamp);
    ViewRequest request = view();
    request.frame_id = 1;
    try {
        (void)live.render(request);
        ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("guides are 2x2, its radiance 64x48"), std::string::npos) << e.what();
    }
    const FrameSource bad_depth = [this](const ViewRequest& v, std::uint64_t s, PackedPixels f) {
        DispatchedFrame frame = source()(v, s, f);
        for (std::size_t i = 0; i < frame.guides.hit.size(); ++i)
            if (frame.guides.hit[i]) frame.guides.depth[i] = std::numeric_limits<float>::quiet_NaN();
        return frame;
    };
    LiveFrames nan_depth(bad_depth, options, 1.f, ToneMap::clamp);
    try {
        (void)nan_depth.render(request);
        ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("guides.depth"), std::string::npos) << e.what();
    }
}

TEST(LiveOptions, BadDenoiseOptionsAreRefusedNamingTheField) {
    const FrameSource none = [](const ViewRequest&, std::uint64_t, PackedPixels) { return DispatchedFrame{}; };
    const auto message = [&](const LiveOptions& o) {
        try {
            LiveFrames live(none, o, 1.f, ToneMap::clamp);
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    LiveOptions zero;
    zero.denoise_max_spp = 0;
    EXPECT_NE(message(zero).find("denoise_max_spp"), std::string::npos) << message(zero);
    LiveOptions levels;
    levels.denoise_params.iterations = AtrousParams::kMaxIterations + 1;
    EXPECT_NE(message(levels).find("iterations"), std::string::npos) << message(levels);
    LiveOptions sigma;
    sigma.denoise_params.sigma_colour = std::nanf("");
    EXPECT_NE(message(sigma).find("sigma_colour"), std::string::npos) << message(sigma);
    LiveOptions threads;
    threads.denoise_params.threads = -1;
    EXPECT_NE(message(threads).find("threads"), std::string::npos) << message(threads);
    LiveOptions alpha;
    alpha.temporal_params.alpha = 0.0f;
    EXPECT_NE(message(alpha).find("temporal_params"), std::string::npos) << message(alpha);
    EXPECT_NE(message(alpha).find("alpha"), std::string::npos) << message(alpha);
    LiveOptions blended;
    blended.blended_denoise_iterations = AtrousParams::kMaxIterations + 1;
    EXPECT_NE(message(blended).find("blended_denoise_iterations"), std::string::npos) << message(blended);
    LiveOptions sparse;
    sparse.shading_one_in = 0;
    EXPECT_NE(message(sparse).find("shading_one_in"), std::string::npos) << message(sparse);
}

TEST(LiveOptions, BadOptionsAreRefused) {
    const FrameSource none = [](const ViewRequest&, std::uint64_t, PackedPixels) { return DispatchedFrame{}; };
    LiveOptions negative;
    negative.frame_time_s = -1;
    EXPECT_THROW(LiveFrames(none, negative, 1.f, ToneMap::clamp), std::invalid_argument);
    LiveOptions zero;
    zero.converged_spp = 0;
    EXPECT_THROW(LiveFrames(none, zero, 1.f, ToneMap::clamp), std::invalid_argument);
    LiveOptions no_first_pass;
    no_first_pass.still_first_pass_spp = 0;
    EXPECT_THROW(LiveFrames(none, no_first_pass, 1.f, ToneMap::clamp), std::invalid_argument);
    EXPECT_THROW(LiveFrames(FrameSource{}, {}, 1.f, ToneMap::clamp), std::invalid_argument);
    LiveOptions whole_period;
    whole_period.pace_share = 1.0;  // nothing left for the hand-off
    EXPECT_THROW(LiveFrames(none, whole_period, 1.f, ToneMap::clamp), std::invalid_argument);
    LiveOptions below_target;
    below_target.max_pace_factor = 0.5;
    EXPECT_THROW(LiveFrames(none, below_target, 1.f, ToneMap::clamp), std::invalid_argument);
}

}  // namespace
}  // namespace mogao
