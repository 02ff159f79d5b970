// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/request_policy.h"

#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

#include "common/request_limits.h"

namespace mogao {
namespace {

constexpr LightCounts kGrotto{1, 3, 0, true};  // sun, three lamps, sky

ViewRequest request(int w, int h, int spp, int bounces = 0, int ao = 0) {
    ViewRequest r;
    r.size = {w, h};
    r.quality.spp = spp;
    r.quality.max_bounces = bounces;
    r.quality.ao_samples = ao;
    return r;
}

TEST(RequestPolicy, EstimateCountsCameraShadowAndBounceRays) {
    // 10x10 px, 2 spp, 1 bounce: per sample 1 camera + 2 vertices x (1 + 3 + 1 sky) + 1 bounce = 12.
    EXPECT_DOUBLE_EQ(estimated_rays(request(10, 10, 2, 1), kGrotto), 100 * 2 * 12.0);
    // AO samples replace the one sky ray; area lights count their samples.
    ViewRequest r = request(10, 10, 1, 0, 8);
    r.quality.area_light_samples = 4;
    EXPECT_DOUBLE_EQ(estimated_rays(r, {0, 0, 2, true}), 100 * (1 + 2 * 4 + 8.0));
    // The resolution scale counts as rendered pixels.
    r = request(100, 100, 1);
    r.quality.resolution_scale = 0.5;
    EXPECT_DOUBLE_EQ(estimated_rays(r, {}), 50 * 50 * 1.0);
}

TEST(RequestPolicy, ARequestWithinBoundsIsUntouched) {
    const ViewRequest r = request(960, 540, 2, 1, 4);
    const PolicyDecision d = apply_request_policy(r, kGrotto, RequestPolicy{});
    EXPECT_FALSE(d.degraded) << d.changes;
    EXPECT_EQ(d.view.quality.spp, 2);
    EXPECT_EQ(d.view.quality.max_bounces, 1);
    EXPECT_DOUBLE_EQ(d.view.quality.resolution_scale, 1.0);
    EXPECT_DOUBLE_EQ(d.rendered_rays, d.requested_rays);
}

// A hostile request: valid by request_limits, minutes of work for any farm.
TEST(RequestPolicy, TheLargestValidRequestIsDegradedIntoTheBudget) {
    namespace L = request_limits;
    ViewRequest r = request(L::kImageSide.max, L::kImageSide.max, L::kSpp.max, L::kMaxBounces.max, L::kAoSamples.max);
    r.quality.area_light_samples = L::kAreaLightSamples.max;
    const LightCounts lights{1, 3, 2, true};
    const RequestPolicy policy;
    const PolicyDecision d = apply_request_policy(r, lights, policy);
    ASSERT_TRUE(d.degraded);
    EXPECT_LE(d.rendered_rays, policy.max_gigarays * 1e9);
    const ImageSize size = render_size(d.view);
    EXPECT_LE(double(size.width) * size.height, policy.max_megapixels * 1e6);
    EXPECT_GE(std::min(size.width, size.height), L::kLinkImageSide.min) << "still a frame the link carries";
    validate_view_request(d.view);
    // spp goes first, resolution last: every knob that changed is named with before and after.
    EXPECT_NE(d.changes.find("spp 4096 -> "), std::string::npos) << d.changes;
    EXPECT_NE(d.changes.find("max_bounces 64 -> "), std::string::npos) << d.changes;
    EXPECT_NE(d.changes.find("resolution_scale 1 -> "), std::string::npos) << d.changes;
    EXPECT_GT(d.requested_rays, 1e15);
}

TEST(RequestPolicy, NoiseIsTradedBeforeResolution) {
    // 1080p at 64 spp, direct light: fits once spp is lowered, so the resolution stays.
    const RequestPolicy policy{8.3, 0.05};
    const PolicyDecision d = apply_request_policy(request(1920, 1080, 64), kGrotto, policy);
    ASSERT_TRUE(d.degraded);
    EXPECT_LT(d.view.quality.spp, 64);
    EXPECT_GE(d.view.quality.spp, 1);
    EXPECT_DOUBLE_EQ(d.view.quality.resolution_scale, 1.0) << d.changes;
    EXPECT_LE(d.rendered_rays, 0.05e9);
    // Halving stops at the first spp that fits: twice as many would not.
    ViewRequest twice = d.view;
    twice.quality.spp *= 2;
    EXPECT_GT(estimated_rays(twice, kGrotto), 0.05e9);
}

TEST(RequestPolicy, PixelBoundCutsTheScaleOnly) {
    const RequestPolicy policy{1.0, 100.0};
    const PolicyDecision d = apply_request_policy(request(4000, 4000, 1), {}, policy);
    const ImageSize size = render_size(d.view);
    EXPECT_LE(double(size.width) * size.height, 1e6);
    EXPECT_GT(double(size.width) * size.height, 0.95e6) << "cut to what fits, not far below";
    EXPECT_EQ(d.view.quality.spp, 1);
}

// The resolution floor bounds the ray bound's cut only: a ray bound no floor fits leaves the scale at
// the floor (over the ray estimate), and a pixel bound below the floor still holds.
TEST(RequestPolicy, TheResolutionFloorHoldsAgainstRaysNotPixels) {
    RequestPolicy policy{100.0, 1e-6};  // 1000 rays: far below any frame
    policy.min_resolution_scale = 0.5;
    const PolicyDecision rays = apply_request_policy(request(400, 300, 4), {}, policy);
    EXPECT_DOUBLE_EQ(rays.view.quality.resolution_scale, 0.5);
    EXPECT_EQ(rays.view.quality.spp, 1);  // the other knobs lowered first
    RequestPolicy pixels{1.0, 100.0};     // 1 Mpixel: a quarter of the scale of 4000 x 4000
    pixels.min_resolution_scale = 0.5;
    const PolicyDecision p = apply_request_policy(request(4000, 4000, 1), {}, pixels);
    const ImageSize size = render_size(p.view);
    EXPECT_LE(double(size.width) * size.height, 1e6);
    RequestPolicy bad;
    bad.min_resolution_scale = 1.5;
    EXPECT_THROW(bad.validate(), std::invalid_argument);
}

TEST(RequestPolicy, BadBoundsAreNamed) {
    for (const RequestPolicy& p : {RequestPolicy{0.0, 1.0}, RequestPolicy{1.0, -1.0},
                                   RequestPolicy{std::numeric_limits<double>::quiet_NaN(), 1.0}}) {
        try {
            p.validate();
            ADD_FAILURE() << "accepted";
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find("RequestPolicy.max_"), std::string::npos) << e.what();
        }
    }
}

}  // namespace
}  // namespace mogao
