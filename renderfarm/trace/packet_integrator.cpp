// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/trace/packet_integrator.h"

#include <algorithm>
#include <limits>
#include <vector>

#include <embree3/rtcore.h>

#include "renderfarm/trace/embree_packets.h"
#include "renderfarm/trace/radiance_cache.h"

namespace mogao {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

struct Lane {
    SurfaceHit hit;
    Eigen::Vector3f wo;
    Eigen::Vector3f throughput = Eigen::Vector3f::Ones();
    bool alive = false;
};

// Scratch of one thread, reused across packets (no allocation per packet once warm).
struct Scratch {
    std::vector<ShadowQuery> queries;
    std::vector<int> lane_of;            // per query
    std::vector<std::uint64_t> order;    // sort keys: group, occurrence, lane, query index
    std::vector<unsigned char> blocked;  // per query
};

void record(RecordedRays* log, const int* valid, const RTCRay16& r, bool occlusion, bool coherent, int depth) {
    if (log == nullptr) return;
    RecordedPacket& p = log->packets.emplace_back();
    p.occlusion = occlusion;
    p.coherent = coherent;
    p.depth = static_cast<std::uint8_t>(std::min(depth, 255));
    for (std::size_t l = 0; l < kPacketLanes; ++l) {
        p.valid[l] = valid[l];
        p.org_x[l] = r.org_x[l];
        p.org_y[l] = r.org_y[l];
        p.org_z[l] = r.org_z[l];
        p.dir_x[l] = r.dir_x[l];
        p.dir_y[l] = r.dir_y[l];
        p.dir_z[l] = r.dir_z[l];
        p.tfar[l] = r.tfar[l];
    }
}

void set_lane(RTCRay16& r, std::size_t l, const Eigen::Vector3f& org, const Eigen::Vector3f& dir, float tfar) {
    r.org_x[l] = org.x();
    r.org_y[l] = org.y();
    r.org_z[l] = org.z();
    r.dir_x[l] = dir.x();
    r.dir_y[l] = dir.y();
    r.dir_z[l] = dir.z();
    r.tnear[l] = 0.0f;  // origins are offset (ray_offset.h)
    r.tfar[l] = tfar;
    r.time[l] = 0.0f;
    r.mask[l] = 0xFFFFFFFFu;
    r.id[l] = static_cast<unsigned>(l);
    r.flags[l] = 0;
}

// Traces every query of `s` in packets of (group, occurrence), each lane at its own position.
// Context flag: INCOHERENT. The rays leave scattered hit points, and Embree's COHERENT mode (meant
// for camera-like rays: Embree 3 API, RTCIntersectContextFlags) traced the same shadow packets
// about twice as slowly (docs/renderer.md, "Ray flags"); frame.coherent_shadow_packets keeps that
// former flag for light groups as the benchmark's baseline.
void trace_queries(const FrameContext& frame, Scratch& s, std::uint64_t& rays, RecordedRays* log, int depth) {
    const std::size_t n = s.queries.size();
    s.blocked.assign(n, 0);
    s.order.clear();
    std::array<std::uint32_t, kPacketLanes * 64> occurrence{};  // per lane and group (-1..62)
    for (std::size_t q = 0; q < n; ++q) {
        const auto lane = static_cast<std::uint64_t>(s.lane_of[q]);
        const auto group = static_cast<std::uint64_t>(s.queries[q].group + 1);
        const std::uint64_t occ = occurrence[lane * 64 + group]++;
        s.order.push_back((group << 58) | (occ << 36) | (lane << 32) | q);
    }
    std::sort(s.order.begin(), s.order.end());
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    for (std::size_t begin = 0; begin < n;) {
        const std::uint64_t packet_key = s.order[begin] >> 36;
        std::size_t end = begin;
        alignas(64) std::array<int, kPacketLanes> valid{};
        RTCRay16 ray{};
        while (end < n && (s.order[end] >> 36) == packet_key) {
            const auto q = static_cast<std::size_t>(s.order[end] & 0xFFFFFFFFu);
            const auto l = static_cast<std::size_t>((s.order[end] >> 32) & 0xFu);
            set_lane(ray, l, s.queries[q].origin, s.queries[q].direction, s.queries[q].tfar);
            valid[l] = -1;
            ++end;
        }
        const bool coherent = frame.coherent_shadow_packets && (packet_key >> 22) != 0;  // not the environment
        context.flags = coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
        record(log, valid.data(), ray, true, coherent, depth);
        if (log != nullptr && begin != 0) log->packets.back().starts_call = false;  // same vertex, same call
        occluded16_at(frame.packet_width, valid.data(), frame.scene->root(), &context, ray);
        for (std::size_t k = begin; k < end; ++k) {
            const auto q = static_cast<std::size_t>(s.order[k] & 0xFFFFFFFFu);
            const auto l = static_cast<std::size_t>((s.order[k] >> 32) & 0xFu);
            s.blocked[q] = ray.tfar[l] < 0.0f ? 1 : 0;  // Embree sets tfar = -inf on any hit
        }
        rays += end - begin;
        begin = end;
    }
}

// Drops the queries whose light group a lane knows; a known-visible one adds its contribution.
void apply_gates(const ShadowGates& gates, Scratch& s, std::array<Eigen::Vector3f, kPacketLanes>& radiance) {
    std::size_t kept = 0;
    for (std::size_t q = 0; q < s.queries.size(); ++q) {
        const auto l = static_cast<std::size_t>(s.lane_of[q]);
        const int g = s.queries[q].group;
        const auto bit = g >= 0 && g < kVisibilityGroups ? static_cast<std::uint8_t>(1u << g) : std::uint8_t{0};
        if ((gates.known_visible[l] & bit) != 0) {
            radiance[l] += s.queries[q].contribution;
            continue;
        }
        if ((gates.known_blocked[l] & bit) != 0) continue;
        s.queries[kept] = s.queries[q];
        s.lane_of[kept] = s.lane_of[q];
        ++kept;
    }
    s.queries.resize(kept);
    s.lane_of.resize(kept);
}

void record_outcomes(const Scratch& s, ShadowGates& gates) {
    for (std::size_t q = 0; q < s.queries.size(); ++q) {
        const int g = s.queries[q].group;
        if (g < 0 || g >= kVisibilityGroups) continue;
        const auto l = static_cast<std::size_t>(s.lane_of[q]);
        const auto bit = static_cast<std::uint8_t>(1u << g);
        (s.blocked[q] != 0 ? gates.rays_blocked[l] : gates.rays_visible[l]) |= bit;
    }
}

// Next-event estimation of every live lane; returns which lanes sample a bounce.
void direct_light(const FrameContext& frame, std::array<Lane, kPacketLanes>& lanes,
                  std::array<ShadingVertex, kPacketLanes>& vertices, bool bounce_follows,
                  std::array<PixelSampler, kPacketLanes>& rngs, std::array<Eigen::Vector3f, kPacketLanes>& radiance,
                  Scratch& s, std::uint64_t& rays, RecordedRays* log, int depth, DirectParts parts = DirectParts::kAll,
                  ShadowGates* gates = nullptr) {
    s.queries.clear();
    s.lane_of.clear();
    const bool training_vertex = frame.cache_training && depth == 0;  // integrator.h, cache_training
    if (training_vertex) parts = DirectParts::kEnvironmentOnly;
    for (std::size_t l = 0; l < kPacketLanes; ++l) {
        if (!lanes[l].alive) continue;
        vertices[l] = make_vertex(frame, lanes[l].hit, lanes[l].wo);
        if (training_vertex) vertices[l].material = white_lambert();
        direct_light_queries(frame, vertices[l], lanes[l].throughput, bounce_follows, rngs[l], s.queries, radiance[l],
                             parts);
        s.lane_of.resize(s.queries.size(), static_cast<int>(l));
    }
    if (gates != nullptr) apply_gates(*gates, s, radiance);
    trace_queries(frame, s, rays, log, depth);
    if (gates != nullptr) record_outcomes(s, *gates);
    for (std::size_t q = 0; q < s.queries.size(); ++q) {
        if (s.blocked[q] == 0) radiance[static_cast<std::size_t>(s.lane_of[q])] += s.queries[q].contribution;
    }
}

// Samples and traces the bounce of every live lane as one packet; lanes that end die.
void bounce(const FrameContext& frame, std::array<Lane, kPacketLanes>& lanes,
            const std::array<ShadingVertex, kPacketLanes>& vertices, std::array<PixelSampler, kPacketLanes>& rngs,
            std::array<Eigen::Vector3f, kPacketLanes>& radiance, std::uint64_t& rays, RecordedRays* log, int depth) {
    alignas(64) std::array<int, kPacketLanes> valid{};
    std::array<Bounce, kPacketLanes> bounces;
    RTCRayHit16 packet{};
    int active = 0;
    for (std::size_t l = 0; l < kPacketLanes; ++l) {
        if (!lanes[l].alive) continue;
        if (!sample_bounce(frame, vertices[l], lanes[l].throughput, depth, rngs[l], bounces[l])) {
            lanes[l].alive = false;
            continue;
        }
        set_lane(packet.ray, l, vertices[l].origin, bounces[l].direction, kInfinity);
        packet.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
        packet.hit.instID[0][l] = RTC_INVALID_GEOMETRY_ID;
        valid[l] = -1;
        ++active;
    }
    if (active == 0) return;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    record(log, valid.data(), packet.ray, false, false, depth);
    intersect16_at(frame.packet_width, valid.data(), frame.scene->root(), &context, packet);
    rays += static_cast<std::uint64_t>(active);
    for (std::size_t l = 0; l < kPacketLanes; ++l) {
        if (valid[l] == 0) continue;
        const bool escaped = packet.hit.geomID[l] == RTC_INVALID_GEOMETRY_ID;
        const float t = packet.ray.tfar[l];
        if (!(frame.cache_training && depth == 0)) {  // a training vertex leaves the lights to the pixel
            radiance[l] += bounce_emission(frame, vertices[l], bounces[l].direction, escaped ? kInfinity : t,
                                           bounces[l].throughput);
        }
        if (escaped && environment_from_bounce(frame, true) && frame.lights->has_environment)
            radiance[l] += bounces[l].throughput.cwiseProduct(frame.lights->environment);
        if (escaped) {
            lanes[l].alive = false;  // see integrator.h
            continue;
        }
        lanes[l].hit =
            frame.scene->surface(vertices[l].origin, bounces[l].direction, t, packet.hit.instID[0][l],
                                 packet.hit.geomID[l], packet.hit.primID[l], packet.hit.u[l], packet.hit.v[l],
                                 Eigen::Vector3f(packet.hit.Ng_x[l], packet.hit.Ng_y[l], packet.hit.Ng_z[l]),
                                 vertices[l].hit->cone_width + frame.cone_spread * t);
        lanes[l].throughput = bounces[l].throughput;
        lanes[l].wo = -bounces[l].direction;
    }
}

std::array<Lane, kPacketLanes> lanes_of(const PacketHits& hits) {
    std::array<Lane, kPacketLanes> lanes;
    for (std::size_t l = 0; l < kPacketLanes; ++l) {
        lanes[l].alive = hits.alive[l];
        if (!hits.alive[l]) continue;
        lanes[l].hit = hits.hit[l];
        lanes[l].wo = hits.wo[l];
    }
    return lanes;
}

}  // namespace

void light_packet(const FrameContext& frame, const PacketHits& hits, std::array<PixelSampler, kPacketLanes>& rngs,
                  std::array<Eigen::Vector3f, kPacketLanes>& radiance, std::uint64_t& rays, ShadowGates* gates) {
    thread_local Scratch scratch;
    std::array<Lane, kPacketLanes> lanes = lanes_of(hits);
    std::array<ShadingVertex, kPacketLanes> vertices;
    direct_light(frame, lanes, vertices, false, rngs, radiance, scratch, rays, nullptr, 0, DirectParts::kLightsOnly,
                 gates);
}

void radiance_packet(const FrameContext& frame, const PacketHits& hits, std::array<PixelSampler, kPacketLanes>& rngs,
                     std::array<Eigen::Vector3f, kPacketLanes>& radiance, std::uint64_t& rays, RecordedRays* log) {
    thread_local Scratch scratch;
    std::array<Lane, kPacketLanes> lanes = lanes_of(hits);
    std::array<ShadingVertex, kPacketLanes> vertices;
    for (int depth = 0;; ++depth) {
        const bool bounce_follows = depth < frame.max_bounces;
        direct_light(frame, lanes, vertices, bounce_follows, rngs, radiance, scratch, rays, log, depth);
        if (!bounce_follows) break;
        bounce(frame, lanes, vertices, rngs, radiance, rays, log, depth);
        if (std::none_of(lanes.begin(), lanes.end(), [](const Lane& l) { return l.alive; })) break;
    }
}

}  // namespace mogao
