// SPDX-License-Identifier: Apache-2.0
#include <gtest/gtest.h>

#include "common/quality_preset.h"
#include "common/request_limits.h"

namespace mogao {
namespace {

// Rays per pixel of a request, the request policy's upper bound (renderfarm/farm/request_policy.h):
// spp x (1 + (1 + bounces) x shadow rays per vertex + bounces), shadow rays ~ AO + area samples.
double rays_per_pixel(const Quality& q) {
    const double shadow = 1.0 + q.ao_samples + q.area_light_samples;
    return q.resolution_scale * q.resolution_scale * q.spp * (1.0 + (1.0 + q.max_bounces) * shadow + q.max_bounces);
}

TEST(QualityPreset, EveryPresetIsAValidRequestAndTheyGoFromFastToAccurate) {
    ASSERT_EQ(quality_presets().size(), 3u);
    double previous_rays = 0.0;
    int previous_converged = 0;
    for (const QualityPreset& p : quality_presets()) {
        ViewRequest request;
        request.size = {960, 540};
        request.quality = p.request;
        EXPECT_NO_THROW(validate_view_request(request)) << p.name;
        EXPECT_GT(rays_per_pixel(p.request), previous_rays) << p.name << " is not dearer than the preset before it";
        EXPECT_GE(p.converged_spp, previous_converged) << p.name;
        EXPECT_GE(p.frame_time_ms, 0.0) << p.name;
        previous_rays = rays_per_pixel(p.request);
        previous_converged = p.converged_spp;
    }
    // Only the fastest preset must hold a frame-time target: it is what fluid motion means.
    EXPECT_GT(quality_presets().front().frame_time_ms, 0.0);
    EXPECT_EQ(quality_presets().back().frame_time_ms, 0.0);
}

// The radiance cache is biased (renderfarm/trace/radiance_cache.h): only presets that trade accuracy
// for a frame-time target may use it, and the fastest one must, or its moving frames pay for full
// paths; the most accurate preset traces every frame unbiased and keeps 4:4:4 chroma.
TEST(QualityPreset, OnlyPresetsWithAFrameTimeTargetUseTheBiasedRadianceCache) {
    for (const QualityPreset& p : quality_presets()) {
        if (p.radiance_cache) {
            EXPECT_GT(p.frame_time_ms, 0.0) << p.name << " uses the radiance cache";
        }
    }
    EXPECT_TRUE(quality_presets().front().radiance_cache);
    EXPECT_TRUE(quality_presets().front().denoise);
    EXPECT_FALSE(quality_presets().back().radiance_cache);
    EXPECT_TRUE(quality_presets().back().chroma_444);
}

TEST(QualityPreset, FindsByNameAndRefusesOthers) {
    ASSERT_NE(quality_preset("interactive"), nullptr);
    EXPECT_EQ(quality_preset("interactive")->name, "interactive");
    EXPECT_EQ(quality_preset("exhibit")->name, "exhibit");
    EXPECT_EQ(quality_preset("Interactive"), nullptr);
    EXPECT_EQ(quality_preset(""), nullptr);
    EXPECT_EQ(quality_preset_names(), "interactive, balanced, exhibit");
}

}  // namespace
}  // namespace mogao
