// SPDX-License-Identifier: Apache-2.0
// Live frame scheduling on a real renderer (one process, no MPI): progressive refinement converges
// toward a converged reference and resets on motion; per-session cost-map streams.
#include "renderfarm/farm/live_frames.h"

#include <cstdio>
#include <set>

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

class LiveFramesTest : public ::testing::Test {
protected:
    LiveFramesTest() : scene_(lit_scene()), renderer_(scene_) {}

    // The stand-in for the FrameDispatcher: the whole frame on this thread, and a record of the calls.
    FrameSource source() {
        return [this](const ViewRequest& view, std::uint64_t stream, PackedPixels format) {
            calls_.push_back({view, stream});
            renderer_.begin_frame(view);
            TilePassResult pass = render_tile_pass(renderer_, {PixelRect::whole(renderer_.render_size())}, 16, 2, 1.f,
                                                   ToneMap::clamp, format);
            DispatchedFrame frame;
            if (format == PackedPixels::linear) {
                frame.radiance = RgbFloatImage(renderer_.render_size());
                unpack_linear_rects({PixelRect::whole(frame.radiance.size)}, pass.packed_pixels, frame.radiance);
            } else {
                frame.image = Rgb8Image(renderer_.render_size());
                unpack_rects({PixelRect::whole(frame.image.size)}, pass.packed_pixels, frame.image);
            }
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
    };
    Scene scene_;
    Renderer renderer_;
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
    LiveFrames live(source(), options, 1.f, ToneMap::clamp);
    for (std::uint64_t id = 1; id <= 8; ++id) {
        ViewRequest moving = view(static_cast<double>(id));
        moving.frame_id = id;
        (void)live.render(moving);
    }
    EXPECT_DOUBLE_EQ(calls_.back().view.quality.resolution_scale, 0.5);
    ViewRequest still = view(8.0);
    still.frame_id = 9;
    const LiveFrame frame = live.render(still);
    EXPECT_DOUBLE_EQ(frame.rendered.quality.resolution_scale, 1.0);
    EXPECT_EQ(frame.image.size, (ImageSize{64, 48}));
}

TEST(LiveOptions, BadOptionsAreRefused) {
    const FrameSource none = [](const ViewRequest&, std::uint64_t, PackedPixels) { return DispatchedFrame{}; };
    LiveOptions negative;
    negative.frame_time_s = -1;
    EXPECT_THROW(LiveFrames(none, negative, 1.f, ToneMap::clamp), std::invalid_argument);
    LiveOptions zero;
    zero.converged_spp = 0;
    EXPECT_THROW(LiveFrames(none, zero, 1.f, ToneMap::clamp), std::invalid_argument);
    EXPECT_THROW(LiveFrames(FrameSource{}, {}, 1.f, ToneMap::clamp), std::invalid_argument);
}

}  // namespace
}  // namespace mogao
