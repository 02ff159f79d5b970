// SPDX-License-Identifier: Apache-2.0
// A cached frame's light at the primary hits of a 4x4 camera packet (radiance_cache.h). Per pixel:
//   L = NEE of the lights at the hit, traced (light_packet, with the frame's light estimator:
//       RendererOptions::legacy_light_sampling; no MIS; the glossy lobe's direct light and sharp
//       shadows stay exact. One light chosen per sample by light_selection.h was measured too: its
//       occlusion-blind choice keeps picking the grotto's sun where the walls hide it, and the
//       point lights' rare, heavily weighted samples speckle every frame). A shadow ray towards
//       a light that the pixel's own cell knows (radiance_cache.h, visibility) is not traced: the
//       light adds its unoccluded contribution or nothing; 1 pixel in visibility_recheck_one_in
//       traces anyway, and every traced outcome is deposited in the pixel's cell.
//       A diffuse pixel (no glossy lobe) whose own cell and jittered cell both know every light
//       alike (radiance_cache.h, CellDirect) and that does not recheck takes ρ_d ⊙ D(jittered cell)
//       instead and evaluates no light; a diffuse pixel that evaluated its lights in a cell no
//       shadow edge crosses deposits D = its direct light / ρ_d there.
//     + ρ_d ⊙ W(cell at a jittered position)  (ρ_d = the tinted material's diffuse part,
//       (1 - k_s) a; W the cell's white radiance: the environment and every bounce, i.e. what a
//       path of radiance_packet gathers beyond the first vertex's lights).
// Training: a pixel whose cell is empty, and one pixel in RadianceCacheOptions::train_one_in
// (chosen by a hash of the frame key and the pixel), traces a training path (FrameContext::
// cache_training: white Lambertian first vertex, the request's bounces) and deposits its estimate
// of W in the cell of its (unjittered) hit; a pixel with an empty cell shows that estimate.
// Bias against the path tracer (docs/renderer.md measures it): W is constant over a cell; the
// glossy lobe's indirect light and the environment seen in it are left out (glossy materials get
// their diffuse part's share only); lights with cast_shadows = false are traced as usual.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "renderfarm/trace/integrator.h"
#include "renderfarm/trace/packet_integrator.h"
#include "renderfarm/trace/radiance_cache.h"
#include "renderfarm/trace/sobol.h"

namespace mogao {

// What a cached frame needs besides the FrameContext.
struct CacheFrame {
    const RadianceCache* cache = nullptr;
    Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // the renderer's rebase origin (world metres)
    std::uint64_t frame_key = 0;                       // selects the training pixels
    std::uint64_t order_base = 0;                      // deposits' merge order: order_base + pixel index
    int width = 0;                                     // render width, for the pixel index
};

// Pixel coordinates of a packet's lanes.
struct LanePixels {
    std::array<int, kPacketLanes> x{};
    std::array<int, kPacketLanes> y{};
};

// Whether pixel (x, y) of the frame is one of the 1 in RadianceCacheOptions::train_one_in that
// trace a training path whatever their cell holds (chosen by a hash of the frame key and the pixel).
[[nodiscard]] bool trains_cache(const CacheFrame& cache_frame, int x, int y);

// Adds each alive lane's cached-frame radiance to radiance[l]; appends training estimates to
// `deposits`; `rays` counts every ray traced.
void cached_radiance_packet(const FrameContext& frame, const CacheFrame& cache_frame, const PacketHits& hits,
                            const LanePixels& pixels, std::array<PixelSampler, kPacketLanes>& rngs,
                            std::array<Eigen::Vector3f, kPacketLanes>& radiance, std::uint64_t& rays,
                            std::vector<CacheDeposit>& deposits);

}  // namespace mogao
