// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/trace/cached_packet.h"

#include <numbers>

#include "renderfarm/trace/rng.h"
#include "renderfarm/trace/sampling.h"

namespace mogao {
namespace {

bool trains(const CacheFrame& cf, int x, int y) {
    const auto pixel =
        (static_cast<std::uint64_t>(static_cast<std::uint32_t>(x)) << 32) | static_cast<std::uint32_t>(y);
    const auto one_in = static_cast<std::uint64_t>(cf.cache->options().train_one_in);
    return mix64(cf.frame_key ^ mix64(pixel)) % one_in == 0;
}

}  // namespace

void cached_radiance_packet(const FrameContext& frame, const CacheFrame& cf, const PacketHits& hits,
                            const LanePixels& pixels, std::array<PixelSampler, kPacketLanes>& rngs,
                            std::array<Eigen::Vector3f, kPacketLanes>& radiance, std::uint64_t& rays,
                            std::vector<CacheDeposit>& deposits) {
    light_packet(frame, hits, rngs, radiance, rays);

    const RadianceCache& cache = *cf.cache;
    PacketHits training = hits;
    std::array<std::uint64_t, kPacketLanes> keys{};
    std::array<bool, kPacketLanes> shown{};  // the lane shows its own training estimate (empty cell)
    std::array<Eigen::Vector3f, kPacketLanes> reflectance;
    bool any = false;
    for (std::size_t l = 0; l < kPacketLanes; ++l) {
        training.alive[l] = false;
        if (!hits.alive[l]) continue;
        const SurfaceHit& h = hits.hit[l];
        reflectance[l] = make_vertex(frame, h, hits.wo[l]).material.diffuse * std::numbers::pi_v<float>;
        // Jittered lookup (Binder et al.): a random point of the cell's size around the hit.
        const float size = cache.cell_size(h.cone_width);
        const Eigen::Vector2f u = rngs[l].next2d();
        const Frame tangent(h.shading_normal);
        const Eigen::Vector3f offset = ((u.x() - 0.5f) * tangent.t + (u.y() - 0.5f) * tangent.b) * size;
        Eigen::Vector3f white;
        const bool found = cache.lookup(
            cache.key(cf.origin + (h.position + offset).cast<double>(), h.shading_normal, h.cone_width), white);
        if (found) radiance[l] += reflectance[l].cwiseProduct(white);
        shown[l] = !found;
        if (found && !trains(cf, pixels.x[l], pixels.y[l])) continue;
        training.alive[l] = true;
        keys[l] = cache.key(cf.origin + h.position.cast<double>(), h.shading_normal, h.cone_width);
        any = true;
    }
    if (!any) return;
    FrameContext train_frame = frame;
    train_frame.cache_training = true;
    std::array<Eigen::Vector3f, kPacketLanes> white;
    white.fill(Eigen::Vector3f::Zero());
    radiance_packet(train_frame, training, rngs, white, rays, nullptr);
    for (std::size_t l = 0; l < kPacketLanes; ++l) {
        if (!training.alive[l]) continue;
        const auto pixel = static_cast<std::uint64_t>(pixels.y[l]) * static_cast<std::uint64_t>(cf.width) +
                           static_cast<std::uint64_t>(pixels.x[l]);
        deposits.push_back({keys[l], cf.order_base + pixel, white[l]});
        if (shown[l]) radiance[l] += reflectance[l].cwiseProduct(white[l]);
    }
}

}  // namespace mogao
