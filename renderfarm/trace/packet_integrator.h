// SPDX-License-Identifier: Apache-2.0
// The integrator of integrator.h over the 16 lanes of a 4x4 camera packet at once, so that
// secondary rays are traced as packets (Embree's rtcOccluded16 / rtcIntersect16) instead of one
// at a time. At every path depth: each live lane turns its vertex into shadow queries
// (direct_light_queries); the queries of all lanes are grouped per light (and the environment),
// the k-th query of a lane for light g going into packet (g, k) at the lane's own position, so a
// packet holds rays from neighbouring pixels towards the same light (coherent: Wald et al.,
// "Interactive Rendering with Coherent Ray Tracing", EG 2001, §3; Embree's packet API); then each
// lane adds its unoccluded contributions in query order, and the bounce rays of all lanes are
// traced as one packet. Random numbers and the order of every sum per lane are those of
// radiance_at, so a lane's value does not depend on its neighbours (renderer determinism) and
// equals the single-ray path's but where Embree's packet and single-ray kernels disagree on a hit.
#pragma once

#include <array>
#include <cstdint>

#include <Eigen/Core>

#include "renderfarm/trace/integrator.h"
#include "renderfarm/trace/recorded_rays.h"
#include "renderfarm/trace/render_scene.h"
#include "renderfarm/trace/sobol.h"

namespace mogao {

inline constexpr int kPacketLanes = 16;

// Primary hits of a packet: `alive[l]` lanes have `hit[l]` seen along -wo[l].
struct PacketHits {
    std::array<SurfaceHit, kPacketLanes> hit;
    std::array<Eigen::Vector3f, kPacketLanes> wo;
    std::array<bool, kPacketLanes> alive{};
};

// What each lane already knows of its lights' visibility (bit g: light group g, the light's index
// in the frame's light set, groups 0..7; radiance_cache.h's CellVisibility), and what it traced.
struct ShadowGates {
    std::array<std::uint8_t, kPacketLanes> known_visible{};  // in: add g's contribution, trace nothing
    std::array<std::uint8_t, kPacketLanes> known_blocked{};  // in: g adds nothing, trace nothing
    std::array<std::uint8_t, kPacketLanes> rays_visible{};   // out: g had an unoccluded ray traced
    std::array<std::uint8_t, kPacketLanes> rays_blocked{};   // out: g had an occluded ray traced
};

// Adds to radiance[l] (for alive lanes) next-event estimation of the lights only (no environment,
// no bounce follows, so no MIS with one) at each lane's hit: the radiance cache's per-pixel part.
// With `gates`, shadow queries whose light a lane knows are not traced (their unoccluded
// contribution is added, or nothing), and the outcomes of the traced ones are reported.
void light_packet(const FrameContext& frame, const PacketHits& hits, std::array<PixelSampler, kPacketLanes>& rngs,
                  std::array<Eigen::Vector3f, kPacketLanes>& radiance, std::uint64_t& rays,
                  ShadowGates* gates = nullptr);

// Adds to radiance[l] (for alive lanes) the radiance_at value of each lane; `rays` counts every
// ray traced; `log` (benchmarks only, may be null) receives every packet traced.
void radiance_packet(const FrameContext& frame, const PacketHits& hits, std::array<PixelSampler, kPacketLanes>& rngs,
                     std::array<Eigen::Vector3f, kPacketLanes>& radiance, std::uint64_t& rays, RecordedRays* log);

}  // namespace mogao
