// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/trace/cached_packet.h"

#include <numbers>

#include "renderfarm/trace/rng.h"
#include "renderfarm/trace/sampling.h"

namespace mogao {
namespace {

std::uint64_t pixel_hash(const CacheFrame& cf, int x, int y, std::uint64_t salt) {
    const auto pixel =
        (static_cast<std::uint64_t>(static_cast<std::uint32_t>(x)) << 32) | static_cast<std::uint32_t>(y);
    return mix64(cf.frame_key ^ mix64(pixel ^ salt));
}

// A pixel of a cell that knows its lights still traces them, 1 in visibility_recheck_one_in.
bool rechecks(const CacheFrame& cf, int x, int y) {
    constexpr std::uint64_t kSalt = 0x9E3779B97F4A7C15ull;  // independent of the training choice
    return pixel_hash(cf, x, y, kSalt) % static_cast<std::uint64_t>(cf.cache->options().visibility_recheck_one_in) == 0;
}

// Each alive lane's cells: its own (unjittered: training and visibility) and the jittered one its
// cached light is read from (Binder et al.: a random point of the cell's size around the hit).
struct LaneCells {
    std::array<std::uint64_t, kPacketLanes> own{};
    std::array<std::uint64_t, kPacketLanes> jittered{};
};

LaneCells cells_of(const CacheFrame& cf, const PacketHits& hits, std::array<PixelSampler, kPacketLanes>& rngs) {
    const RadianceCache& cache = *cf.cache;
    LaneCells cells;
    for (std::size_t l = 0; l < kPacketLanes; ++l) {
        if (!hits.alive[l]) continue;
        const SurfaceHit& h = hits.hit[l];
        const int level = cache.cell_level(h.cone_width);
        const float size = cache.level_size(level);
        const Eigen::Vector2f u = rngs[l].next2d();
        const Frame tangent(h.shading_normal);
        const Eigen::Vector3f offset = ((u.x() - 0.5f) * tangent.t + (u.y() - 0.5f) * tangent.b) * size;
        cells.own[l] = cache.key_at_level(cf.origin + h.position.cast<double>(), h.shading_normal, level);
        cells.jittered[l] =
            cache.key_at_level(cf.origin + (h.position + offset).cast<double>(), h.shading_normal, level);
        cache.prefetch(cells.own[l]);
        cache.prefetch(cells.jittered[l]);
    }
    return cells;
}

// What each alive lane reads of its two cells (one probe each; the same read when they coincide).
struct LaneReads {
    std::array<CellRead, kPacketLanes> own;
    std::array<CellRead, kPacketLanes> jittered;
};

LaneReads reads_of(const CacheFrame& cf, const PacketHits& hits, const LaneCells& cells) {
    LaneReads reads;
    for (std::size_t l = 0; l < kPacketLanes; ++l) {
        if (!hits.alive[l]) continue;
        reads.own[l] = cf.cache->read(cells.own[l]);
        reads.jittered[l] = cells.jittered[l] == cells.own[l] ? reads.own[l] : cf.cache->read(cells.jittered[l]);
    }
    return reads;
}

// What each lane's own cell knows of its lights (nothing for a pixel that rechecks).
ShadowGates gates_of(const CacheFrame& cf, const PacketHits& hits, const LanePixels& pixels, const LaneReads& reads) {
    ShadowGates gates;
    for (std::size_t l = 0; l < kPacketLanes; ++l) {
        if (!hits.alive[l] || rechecks(cf, pixels.x[l], pixels.y[l])) continue;
        gates.known_visible[l] = reads.own[l].direct.known.visible;
        gates.known_blocked[l] = reads.own[l].direct.known.blocked;
    }
    return gates;
}

// Every light of the frame has a visibility group (so a cell can know them all).
bool lights_tracked(const FrameContext& frame) {
    const LightSet& lights = *frame.lights;
    return lights.directional.size() + lights.point.size() + lights.area.size() <=
           static_cast<std::size_t>(kVisibilityGroups);
}

// Which lanes take their lights' direct light from their cells (radiance_cache.h, CellDirect) and
// which lanes' traced direct light trains their own cell. A lane qualifies when its material is
// diffuse, it does not recheck, its own cell is usable and the jittered cell it reads is usable
// with the same lights known (a jittered read never crosses into another lighting).
struct DirectFromCells {
    std::array<bool, kPacketLanes> used{};
    std::array<bool, kPacketLanes> trains{};
};

DirectFromCells direct_from_cells(const CacheFrame& cf, const PacketHits& hits, const LanePixels& pixels,
                                  const LaneReads& reads, const std::array<ShadingVertex, kPacketLanes>& vertices,
                                  bool allowed, std::array<Eigen::Vector3f, kPacketLanes>& radiance,
                                  const std::array<Eigen::Vector3f, kPacketLanes>& reflectance) {
    DirectFromCells out;
    if (!allowed) return out;
    for (std::size_t l = 0; l < kPacketLanes; ++l) {
        if (!hits.alive[l] || vertices[l].material.glossy) continue;
        const CellDirect& own = reads.own[l].direct;
        out.trains[l] = own.trainable && reflectance[l].minCoeff() > 1e-4f;
        if (!own.usable || rechecks(cf, pixels.x[l], pixels.y[l])) continue;
        const CellDirect& read = reads.jittered[l].direct;
        if (!read.usable || read.known.visible != own.known.visible || read.known.blocked != own.known.blocked)
            continue;
        radiance[l] += reflectance[l].cwiseProduct(read.white);
        out.used[l] = true;
        out.trains[l] = false;
    }
    return out;
}

std::uint64_t pixel_order(const CacheFrame& cf, const LanePixels& pixels, std::size_t l) {
    return cf.order_base + static_cast<std::uint64_t>(pixels.y[l]) * static_cast<std::uint64_t>(cf.width) +
           static_cast<std::uint64_t>(pixels.x[l]);
}

}  // namespace

bool trains_cache(const CacheFrame& cf, int x, int y) {
    return pixel_hash(cf, x, y, 0) % static_cast<std::uint64_t>(cf.cache->options().train_one_in) == 0;
}

void cached_radiance_packet(const FrameContext& frame, const CacheFrame& cf, const PacketHits& hits,
                            const LanePixels& pixels, std::array<PixelSampler, kPacketLanes>& rngs,
                            std::array<Eigen::Vector3f, kPacketLanes>& radiance, std::uint64_t& rays,
                            std::vector<CacheDeposit>& deposits) {
    const LaneCells cells = cells_of(cf, hits, rngs);
    const LaneReads reads = reads_of(cf, hits, cells);
    ShadowGates gates = gates_of(cf, hits, pixels, reads);
    std::array<ShadingVertex, kPacketLanes> vertices;
    std::array<Eigen::Vector3f, kPacketLanes> reflectance;
    for (std::size_t l = 0; l < kPacketLanes; ++l) {
        if (!hits.alive[l]) continue;
        vertices[l] = make_vertex(frame, hits.hit[l], hits.wo[l]);
        reflectance[l] = vertices[l].material.diffuse * std::numbers::pi_v<float>;
    }
    const bool direct_allowed = cf.cache->options().cache_direct && lights_tracked(frame);
    const DirectFromCells from_cells =
        direct_from_cells(cf, hits, pixels, reads, vertices, direct_allowed, radiance, reflectance);
    PacketHits lit = hits;
    for (std::size_t l = 0; l < kPacketLanes; ++l) lit.alive[l] = hits.alive[l] && !from_cells.used[l];
    std::array<Eigen::Vector3f, kPacketLanes> direct_light = radiance;
    light_packet(frame, lit, rngs, radiance, rays, &gates);
    for (std::size_t l = 0; l < kPacketLanes; ++l) direct_light[l] = radiance[l] - direct_light[l];

    PacketHits training = hits;
    std::array<bool, kPacketLanes> shown{};  // the lane shows its own training estimate (empty cell)
    bool any = false;
    for (std::size_t l = 0; l < kPacketLanes; ++l) {
        training.alive[l] = false;
        if (!hits.alive[l]) continue;
        const bool found = reads.jittered[l].has_radiance;
        if (found) radiance[l] += reflectance[l].cwiseProduct(reads.jittered[l].white);
        shown[l] = !found;
        if (found && !trains_cache(cf, pixels.x[l], pixels.y[l])) continue;
        training.alive[l] = true;
        any = true;
    }
    std::array<Eigen::Vector3f, kPacketLanes> white;
    white.fill(Eigen::Vector3f::Zero());
    if (any) {
        FrameContext train_frame = frame;
        train_frame.cache_training = true;
        radiance_packet(train_frame, training, rngs, white, rays, nullptr);
    }
    for (std::size_t l = 0; l < kPacketLanes; ++l) {
        const bool traced = gates.rays_visible[l] != 0 || gates.rays_blocked[l] != 0;
        const bool direct = from_cells.trains[l];
        if (!training.alive[l] && !traced && !direct) continue;
        deposits.push_back(
            {cells.own[l], pixel_order(cf, pixels, l), white[l], training.alive[l], gates.rays_visible[l],
             gates.rays_blocked[l],
             direct ? Eigen::Vector3f(direct_light[l].cwiseQuotient(reflectance[l])) : Eigen::Vector3f::Zero(),
             direct});
        if (shown[l]) radiance[l] += reflectance[l].cwiseProduct(white[l]);
    }
}

}  // namespace mogao
