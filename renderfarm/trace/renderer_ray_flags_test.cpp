// SPDX-License-Identifier: Apache-2.0
// Ray flags: every secondary ray (shadow, environment, bounce) is traced with Embree's INCOHERENT
// context flag, and tracing the light shadow packets with the former COHERENT flag instead
// (RendererOptions::coherent_shadow_packets_baseline, the benchmark's baseline) changes no pixel:
// the flag is a traversal hint, the rays and their hits are the same (Embree 3 API,
// RTCIntersectContextFlags).
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "renderfarm/trace/renderer.h"
#include "renderfarm/trace/test_scenes.h"

namespace mogao {
namespace {

// Every kind of shadow query (sun, point, area, environment) and several bounces.
Scene lit_scene() {
    Scene scene = test::make_sphere_over_floor();
    DirectionalLight sun;
    sun.direction_to_light = Eigen::Vector3d(-0.4, 1.0, 0.3).normalized();
    scene.directional_lights = {sun};
    scene.point_lights = {PointLight{{1.0, 2.0, 1.0}, Rgb(4.0f, 4.0f, 4.0f), true}};
    scene.area_lights = {AreaLight{{-0.5, 2.5, -0.5}, {1.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, Rgb(3.0f, 3.0f, 3.0f), true}};
    scene.environment_lights = {EnvironmentLight{Rgb(0.2f, 0.2f, 0.25f)}};
    return scene;
}

ViewRequest request(int bounces) {
    ViewRequest r = test::look_at({0.3, 2.0, 3.5}, {0.0, 0.6, 0.0}, {40, 32}, 50.0);
    r.quality.spp = 2;
    r.quality.ao_samples = 1;
    r.quality.max_bounces = bounces;
    r.seed = 99;
    return r;
}

struct Rendered {
    RgbFloatImage frame;
    RecordedRays log;
};

Rendered render(Renderer& renderer, const ViewRequest& view, bool coherent_baseline) {
    RendererOptions options;
    options.coherent_shadow_packets_baseline = coherent_baseline;
    renderer.set_path_options(options);
    renderer.begin_frame(view);
    Rendered out{RgbFloatImage(renderer.render_size()), {}};
    (void)renderer.render_recording(PixelRect::whole(out.frame.size), out.frame, out.log);
    return out;
}

bool same_bytes(const RgbFloatImage& a, const RgbFloatImage& b) {
    return a.pixels.size() == b.pixels.size() &&
           std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(float)) == 0;
}

std::size_t coherent_packets(const RecordedRays& log) {
    std::size_t n = 0;
    for (const RecordedPacket& p : log.packets) n += p.coherent ? 1u : 0u;
    return n;
}

TEST(RendererRayFlags, SecondaryRaysIncoherentAndPixelsIdenticalToCoherentBaseline) {
    const Scene scene = lit_scene();
    Renderer renderer(scene, RendererOptions{"threads=1"});
    for (const int bounces : {0, 1, 4}) {
        SCOPED_TRACE("max_bounces " + std::to_string(bounces));
        const Rendered now = render(renderer, request(bounces), false);
        const Rendered before = render(renderer, request(bounces), true);
        ASSERT_GT(now.log.ray_count(), 0u);
        EXPECT_EQ(now.log.ray_count(), before.log.ray_count());
        EXPECT_EQ(coherent_packets(now.log), 0u) << "a secondary packet was traced COHERENT";
        EXPECT_GT(coherent_packets(before.log), 0u) << "the baseline did not trace its light packets COHERENT";
        EXPECT_TRUE(same_bytes(now.frame, before.frame)) << "the ray flag changed a pixel";
    }
}

// The comparison above sees a change of one sample's random numbers: another frame_id (same
// view, other samples) gives different bytes.
TEST(RendererRayFlags, ComparisonDetectsOtherSamples) {
    const Scene scene = lit_scene();
    Renderer renderer(scene, RendererOptions{"threads=1"});
    ViewRequest other = request(1);
    other.frame_id += 1;
    const Rendered a = render(renderer, request(1), false);
    const Rendered b = render(renderer, other, false);
    EXPECT_FALSE(same_bytes(a.frame, b.frame));
}

}  // namespace
}  // namespace mogao
