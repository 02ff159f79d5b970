// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/trace/renderer.h"

#include <array>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <embree3/rtcore.h>

#include "common/request_limits.h"
#include "renderfarm/trace/cached_packet.h"
#include "renderfarm/trace/camera.h"
#include "renderfarm/trace/embree_packets.h"
#include "renderfarm/trace/integrator.h"
#include "renderfarm/trace/light_set.h"
#include "renderfarm/trace/packet_integrator.h"
#include "renderfarm/trace/radiance_cache.h"
#include "renderfarm/trace/render_scene.h"
#include "renderfarm/trace/rng.h"
#include "renderfarm/trace/sampling.h"
#include "renderfarm/trace/shading.h"
#include "renderfarm/trace/sobol.h"

namespace mogao {
namespace {

constexpr int kBlock = 4;  // 4x4 pixels = one rtcIntersect16 packet
constexpr int kLanes = kBlock * kBlock;

// One 4x4 block of the global pixel grid and which of its pixels belong to the rect.
struct Block {
    alignas(64) std::array<int, kLanes> valid{};  // -1 = trace, 0 = masked (Embree convention)
    int x0 = 0;
    int y0 = 0;
    int active = 0;
};

Block make_block(int x0, int y0, const PixelRect& rect) {
    Block block;
    block.x0 = x0;
    block.y0 = y0;
    for (int lane = 0; lane < kLanes; ++lane) {
        const bool inside = rect.contains(x0 + lane % kBlock, y0 + lane / kBlock);
        block.valid[static_cast<std::size_t>(lane)] = inside ? -1 : 0;
        block.active += inside ? 1 : 0;
    }
    return block;
}

std::string describe(const PixelRect& r) {
    return "[" + std::to_string(r.x0) + ", " + std::to_string(r.x1) + ") x [" + std::to_string(r.y0) + ", " +
           std::to_string(r.y1) + ")";
}

}  // namespace

struct Renderer::Impl {
    Impl(const Scene& scene, const RendererOptions& opts)
        : options(opts),
          source_scene(&scene),
          geometry(scene, opts.embree_config, opts.bvh),
          lights(LightSet::from_scene(scene)),
          lighting(lighting_state(scene, 0.0)),
          native_width(native_packet_width(geometry.root())),
          cache(std::make_unique<RadianceCache>(opts.radiance_cache)) {
        materials.reserve(scene.materials.size());
        for (const Material& m : scene.materials) materials.push_back(make_shading_material(m));
    }

    RendererOptions options;
    const Scene* source_scene;  // outlives the Renderer (renderer.h)
    RenderScene geometry;
    LightSet lights;
    std::vector<float> lighting;  // the animated lights' factors `lights` holds (scene.h, lighting_state)
    std::vector<ShadingMaterial> materials;
    int native_width = 16;
    // Shared by every frame; lookups are const, deposits are queued under its mutex (radiance_cache.h).
    std::unique_ptr<RadianceCache> cache;
    std::uint64_t frames_begun = 0;

    // Current frame (set by begin_frame).
    bool ready = false;
    ImageSize size;
    std::optional<CameraSetup> camera;
    CylinderColumns columns;  // filled when options.camera_column_table and spp == 1
    std::uint64_t key = 0;
    int spp = 1;
    bool jitter_samples = true;  // spp > 1 or options.jitter_one_spp
    FrameContext context;
    bool cached = false;  // ViewRequest::radiance_cache: cached_packet.h's light
    CacheFrame cache_frame;
    int shading_one_in = 1;  // ViewRequest's, for cached frames (1 otherwise)
    int shading_phase = 0;

    [[nodiscard]] int packet_width() const { return options.native_packet_width ? native_width : 16; }

    void check_ready() const {
        if (!ready) throw std::logic_error("Renderer: begin_frame() must be called before rendering");
    }

    // Fills the camera rays of one sample index for the lanes of `block` and their random streams.
    void fill_packet(const Block& block, int sample, RTCRayHit16& packet,
                     std::array<PixelSampler, kLanes>& rngs) const {
        const Eigen::Vector3d& origin = geometry.origin();
        for (int lane = 0; lane < kLanes; ++lane) {
            const auto l = static_cast<std::size_t>(lane);
            packet.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
            packet.hit.instID[0][l] = RTC_INVALID_GEOMETRY_ID;
            if (block.valid[l] == 0) continue;
            const int x = block.x0 + lane % kBlock;
            const int y = block.y0 + lane / kBlock;
            rngs[l] = PixelSampler(key, x, y, sample);
            // The pixel's samples are one Sobol' net (a scrambled point at spp 1 too, unless the
            // pixel-centre baseline is asked for: RendererOptions::jitter_one_spp).
            Eigen::Vector2f jitter(0.5f, 0.5f);
            if (jitter_samples) jitter = rngs[l].next2d();
            const Ray ray =
                !jitter_samples && !columns.sin_theta.empty()
                    ? generate_column_ray(*camera, columns, x, y + 0.5)
                    : generate_ray(*camera, x + static_cast<double>(jitter.x()), y + static_cast<double>(jitter.y()));
            const Eigen::Vector3f org = (ray.origin - origin).cast<float>();
            const Eigen::Vector3f dir = ray.direction.cast<float>();
            packet.ray.org_x[l] = org.x();
            packet.ray.org_y[l] = org.y();
            packet.ray.org_z[l] = org.z();
            packet.ray.dir_x[l] = dir.x();
            packet.ray.dir_y[l] = dir.y();
            packet.ray.dir_z[l] = dir.z();
            packet.ray.tnear[l] = 0.0f;
            packet.ray.tfar[l] = std::numeric_limits<float>::infinity();
            packet.ray.time[l] = 0.0f;
            packet.ray.mask[l] = 0xFFFFFFFFu;
            packet.ray.id[l] = static_cast<unsigned>(lane);
            packet.ray.flags[l] = 0;
        }
    }

    void intersect(const Block& block, RTCRayHit16& packet) const {
        RTCIntersectContext context_flags;
        rtcInitIntersectContext(&context_flags);
        context_flags.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        intersect16_at(packet_width(), block.valid.data(), geometry.root(), &context_flags, packet);
    }

    void check_target(const PixelRect& rect, const RgbFloatImage* frame) const {
        check_ready();
        if (rect.x0 < 0 || rect.y0 < 0 || rect.x1 > size.width || rect.y1 > size.height) {
            throw std::invalid_argument("Renderer::render: rect " + describe(rect) + " is outside the render size " +
                                        std::to_string(size.width) + "x" + std::to_string(size.height));
        }
        if (frame != nullptr &&
            (frame->size != size || frame->pixels.size() != static_cast<std::size_t>(size.pixel_count()) * 3)) {
            throw std::invalid_argument("Renderer::render: frame is " + std::to_string(frame->size.width) + "x" +
                                        std::to_string(frame->size.height) + ", render size is " +
                                        std::to_string(size.width) + "x" + std::to_string(size.height));
        }
    }

    void check_window(const PixelRect& rect, const RgbFloatImage& window, int origin_x, int origin_y) const {
        check_target(rect, nullptr);
        const PixelRect placed{origin_x, origin_y, origin_x + window.size.width, origin_y + window.size.height};
        if (rect.empty()) return;
        if (rect.x0 < placed.x0 || rect.y0 < placed.y0 || rect.x1 > placed.x1 || rect.y1 > placed.y1 ||
            window.pixels.size() != static_cast<std::size_t>(window.size.pixel_count()) * 3) {
            throw std::invalid_argument("Renderer::render: rect " + describe(rect) + " is outside the window " +
                                        describe(placed));
        }
    }

    // Primary hits of a traced camera packet; sky lanes get the environment in `sum`.
    void resolve_hits(const Block& block, const RTCRayHit16& packet, PacketHits& hits,
                      std::array<Eigen::Vector3f, kLanes>& sum) const {
        for (std::size_t l = 0; l < kLanes; ++l) {
            hits.alive[l] = false;
            if (block.valid[l] == 0) continue;
            if (packet.hit.geomID[l] == RTC_INVALID_GEOMETRY_ID) {
                sum[l] += lights.environment;  // the sky behind everything
                continue;
            }
            const Eigen::Vector3f org(packet.ray.org_x[l], packet.ray.org_y[l], packet.ray.org_z[l]);
            const Eigen::Vector3f dir(packet.ray.dir_x[l], packet.ray.dir_y[l], packet.ray.dir_z[l]);
            hits.hit[l] = geometry.surface(org, dir, packet.ray.tfar[l], packet.hit.instID[0][l], packet.hit.geomID[l],
                                           packet.hit.primID[l], packet.hit.u[l], packet.hit.v[l],
                                           Eigen::Vector3f(packet.hit.Ng_x[l], packet.hit.Ng_y[l], packet.hit.Ng_z[l]),
                                           context.cone_spread * packet.ray.tfar[l]);
            hits.wo[l] = -dir;
            hits.alive[l] = true;
        }
    }

    // The first camera hit of each valid lane into `guides` (a window from origin_x, origin_y on),
    // resolved as the guide pass resolves its own (guide_buffers.h).
    void store_guides(const Block& block, const RTCRayHit16& packet, const PacketHits& hits, int origin_x, int origin_y,
                      GuideBuffers& guides) const {
        for (std::size_t l = 0; l < kLanes; ++l) {
            if (block.valid[l] == 0) continue;
            const std::size_t i = guides.pixel(block.x0 + static_cast<int>(l) % kBlock - origin_x,
                                               block.y0 + static_cast<int>(l) / kBlock - origin_y);
            if (!hits.alive[l]) {
                guides.set_sky(i);
                continue;
            }
            const SurfaceHit& hit = hits.hit[l];
            Eigen::Vector3f a = materials[hit.material].albedo;
            if (hit.tinted) a = a.cwiseProduct(hit.tint);
            guides.set_surface(i, a.data(), hit.shading_normal.data(), packet.ray.tfar[l]);
        }
    }

    // Renders every sample of one block into `frame` (render()'s body; `log` for benchmarks).
    // `frame` holds the frame's pixels from (origin_x, origin_y) on (0, 0 for a whole frame);
    // `guides`, when given, the first sample's hits at the same place.
    void render_block(const Block& block, RgbFloatImage& frame, TileStats& stats, RecordedRays* log, int origin_x = 0,
                      int origin_y = 0, std::vector<CacheDeposit>* deposits = nullptr,
                      GuideBuffers* guides = nullptr) const {
        std::array<Eigen::Vector3f, kLanes> sum;
        sum.fill(Eigen::Vector3f::Zero());
        std::array<bool, kLanes> unshaded{};
        PacketHits hits;
        for (int sample = 0; sample < spp; ++sample) {
            RTCRayHit16 packet{};  // masked lanes stay zero (defined for tools like valgrind)
            std::array<PixelSampler, kLanes> rngs;
            fill_packet(block, sample, packet, rngs);
            intersect(block, packet);
            stats.rays += static_cast<std::uint64_t>(block.active);
            resolve_hits(block, packet, hits, sum);
            if (sample == 0 && guides != nullptr) store_guides(block, packet, hits, origin_x, origin_y, *guides);
            if (cached && deposits != nullptr) {
                std::array<Eigen::Vector3f, kLanes> radiance;
                radiance.fill(Eigen::Vector3f::Zero());
                LanePixels pixels;
                for (int lane = 0; lane < kLanes; ++lane) {
                    pixels.x[static_cast<std::size_t>(lane)] = block.x0 + lane % kBlock;
                    pixels.y[static_cast<std::size_t>(lane)] = block.y0 + lane / kBlock;
                }
                skip_unshaded(pixels, hits, unshaded);
                cached_radiance_packet(context, cache_frame, hits, pixels, rngs, radiance, stats.rays, *deposits);
                for (std::size_t l = 0; l < kLanes; ++l)
                    if (hits.alive[l]) sum[l] += radiance[l];
                continue;
            }
            if (options.packet_secondary_rays) {
                std::array<Eigen::Vector3f, kLanes> radiance;
                radiance.fill(Eigen::Vector3f::Zero());
                radiance_packet(context, hits, rngs, radiance, stats.rays, log);
                for (std::size_t l = 0; l < kLanes; ++l)
                    if (hits.alive[l]) sum[l] += radiance[l];
                continue;
            }
            for (std::size_t l = 0; l < kLanes; ++l) {
                if (hits.alive[l]) sum[l] += radiance_at(context, hits.hit[l], hits.wo[l], rngs[l], stats.rays, log);
            }
        }
        const float inv_spp = 1.0f / static_cast<float>(spp);
        for (int lane = 0; lane < kLanes; ++lane) {
            if (block.valid[static_cast<std::size_t>(lane)] == 0) continue;
            float* out = frame.at(block.x0 + lane % kBlock - origin_x, block.y0 + lane / kBlock - origin_y);
            const Eigen::Vector3f value = unshaded[static_cast<std::size_t>(lane)]
                                              ? Eigen::Vector3f(kUnshadedRadiance, 0.0f, 0.0f)
                                              : Eigen::Vector3f(sum[static_cast<std::size_t>(lane)] * inv_spp);
            out[0] = value.x();
            out[1] = value.y();
            out[2] = value.z();
        }
    }

    // A sparse cached frame (ViewRequest::shading_one_in): the surface lanes it does not shade stop
    // after their primary hit (their guides are stored) and are marked in `unshaded`. The cache's
    // training pixels are always shaded, so the cache learns as fast as from a full frame.
    void skip_unshaded(const LanePixels& pixels, PacketHits& hits, std::array<bool, kLanes>& unshaded) const {
        if (shading_one_in == 1) return;
        for (std::size_t l = 0; l < kLanes; ++l) {
            if (!hits.alive[l] || shades_pixel(shading_one_in, shading_phase, pixels.x[l], pixels.y[l]) ||
                trains_cache(cache_frame, pixels.x[l], pixels.y[l]))
                continue;
            hits.alive[l] = false;
            unshaded[l] = true;
        }
    }

    // render()'s body once its arguments are checked; queues a cached frame's training estimates.
    TileStats render_rect(const PixelRect& rect, RgbFloatImage& window, int origin_x, int origin_y,
                          GuideBuffers* guides = nullptr) const {
        TileStats stats;
        thread_local std::vector<CacheDeposit> deposits;
        deposits.clear();
        for_each_block(rect, [&](const Block& block) {
            render_block(block, window, stats, nullptr, origin_x, origin_y, &deposits, guides);
        });
        if (!deposits.empty()) cache->deposit(deposits);
        return stats;
    }

    // Visits the 4x4 blocks of the global grid that overlap rect.
    template <typename Visit>
    static void for_each_block(const PixelRect& rect, Visit&& visit) {
        const int bx0 = rect.x0 - rect.x0 % kBlock;
        const int by0 = rect.y0 - rect.y0 % kBlock;
        for (int by = by0; by < rect.y1; by += kBlock) {
            for (int bx = bx0; bx < rect.x1; bx += kBlock) visit(make_block(bx, by, rect));
        }
    }
};

Renderer::Renderer(const Scene& scene, const RendererOptions& options)
    : impl_(std::make_unique<Impl>(scene, options)) {}
Renderer::~Renderer() = default;
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;

void Renderer::set_path_options(const RendererOptions& options) {
    impl_->options.legacy_light_sampling = options.legacy_light_sampling;
    impl_->options.packet_secondary_rays = options.packet_secondary_rays;
    impl_->options.camera_column_table = options.camera_column_table;
    impl_->options.native_packet_width = options.native_packet_width;
    impl_->options.coherent_shadow_packets_baseline = options.coherent_shadow_packets_baseline;
    impl_->options.russian_roulette = options.russian_roulette;
    impl_->options.jitter_one_spp = options.jitter_one_spp;
    impl_->options.jitter_cached_one_spp = options.jitter_cached_one_spp;
    impl_->options.glossy_vndf_sampling = options.glossy_vndf_sampling;
    impl_->options.environment_from_bounce = options.environment_from_bounce;
}

void Renderer::begin_frame(const ViewRequest& request) {
    Impl& s = *impl_;
    const ImageSize size = render_size_for(request);  // validates before any state changes
    const Eigen::Vector3d origin = s.options.rebase_on_eye ? request.pose.eye : Eigen::Vector3d::Zero();
    if (std::vector<float> lighting = lighting_state(*s.source_scene, request.scene_time_s); lighting != s.lighting) {
        // An animated light changed: what the cache learnt (light, and each light's visibility by
        // its index in `lights`) belongs to the old lights, its queued estimates included.
        s.lights = LightSet::from_scene(*s.source_scene, request.scene_time_s);
        s.lighting = std::move(lighting);
        s.cache->clear();
    }
    s.geometry.rebase(origin);
    s.lights.rebase(origin);
    s.size = size;
    s.camera = make_camera_setup(request, size);
    s.key = frame_key(request.seed, request.frame_id);
    s.spp = request.quality.spp;
    s.context = FrameContext{&s.geometry,
                             &s.lights,
                             &s.materials,
                             request.quality.max_bounces,
                             request.quality.ao_samples,
                             request.quality.area_light_samples,
                             s.options.legacy_light_sampling,
                             s.packet_width()};
    s.context.cone_spread = static_cast<float>(camera_cone_spread(*s.camera, s.spp));
    s.context.coherent_shadow_packets = s.options.coherent_shadow_packets_baseline;
    s.context.russian_roulette = s.options.russian_roulette;
    s.context.glossy_vndf = s.options.glossy_vndf_sampling;
    s.context.environment_from_bounce = s.options.environment_from_bounce;
    s.cached = request.radiance_cache;
    s.shading_one_in = s.cached ? request.shading_one_in : 1;
    s.shading_phase = s.cached ? request.shading_phase : 0;
    s.jitter_samples = s.spp > 1 || (s.options.jitter_one_spp && (!s.cached || s.options.jitter_cached_one_spp));
    // Last frame's training estimates join the cache before this frame reads it.
    s.cache->commit();
    ++s.frames_begun;
    s.cache_frame = CacheFrame{s.cache.get(), origin, s.key, s.frames_begun << 32, size.width};
    // The column table holds pixel-centre angles: only for the centre-sampled baseline.
    s.columns =
        s.options.camera_column_table && !s.jitter_samples ? make_cylinder_columns(*s.camera) : CylinderColumns{};
    s.ready = true;
}

const RenderScene& Renderer::render_scene() const { return impl_->geometry; }

ImageSize Renderer::render_size() const {
    impl_->check_ready();
    return impl_->size;
}

bool Renderer::samples_pixel_centres() const {
    impl_->check_ready();
    return !impl_->jitter_samples;
}

TileStats Renderer::render(const PixelRect& rect, RgbFloatImage& frame) const {
    impl_->check_target(rect, &frame);
    return impl_->render_rect(rect, frame, 0, 0);
}

TileStats Renderer::render(const PixelRect& rect, RgbFloatImage& window, int origin_x, int origin_y) const {
    impl_->check_window(rect, window, origin_x, origin_y);
    return impl_->render_rect(rect, window, origin_x, origin_y);
}

TileStats Renderer::render(const PixelRect& rect, RgbFloatImage& window, int origin_x, int origin_y,
                           GuideBuffers& guides) const {
    impl_->check_window(rect, window, origin_x, origin_y);
    const auto n = static_cast<std::size_t>(window.size.pixel_count());
    if (guides.size != window.size || guides.hit.size() != n || guides.depth.size() != n ||
        guides.albedo.size() != 3 * n || guides.normal.size() != 3 * n) {
        throw std::invalid_argument("Renderer::render: guides are " + std::to_string(guides.size.width) + "x" +
                                    std::to_string(guides.size.height) + " (or their buffers hold the wrong count), " +
                                    "the window " + std::to_string(window.size.width) + "x" +
                                    std::to_string(window.size.height));
    }
    return impl_->render_rect(rect, window, origin_x, origin_y, &guides);
}

void Renderer::clear_radiance_cache() { impl_->cache->clear(); }

void Renderer::commit_radiance_cache() { impl_->cache->commit(); }

RadianceCacheStats Renderer::radiance_cache_stats() const { return {impl_->cache->cells(), impl_->cache->dropped()}; }

TileStats Renderer::render_recording(const PixelRect& rect, RgbFloatImage& frame, RecordedRays& log) const {
    const Impl& s = *impl_;
    s.check_target(rect, &frame);
    TileStats stats;
    Impl::for_each_block(rect, [&](const Block& block) { s.render_block(block, frame, stats, &log); });
    return stats;
}

namespace {

RTCRayHit single_ray(const RecordedPacket& p, std::size_t l) {
    RTCRayHit one{};
    one.ray.org_x = p.org_x[l];
    one.ray.org_y = p.org_y[l];
    one.ray.org_z = p.org_z[l];
    one.ray.dir_x = p.dir_x[l];
    one.ray.dir_y = p.dir_y[l];
    one.ray.dir_z = p.dir_z[l];
    one.ray.tfar = p.tfar[l];
    one.ray.mask = 0xFFFFFFFFu;
    one.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    one.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    return one;
}

void replay_packet(const RecordedPacket& p, int width, RTCScene scene, RTCIntersectContext* context) {
    RTCRayHit16 packet{};
    for (std::size_t l = 0; l < kLanes; ++l) {
        packet.ray.org_x[l] = p.org_x[l];
        packet.ray.org_y[l] = p.org_y[l];
        packet.ray.org_z[l] = p.org_z[l];
        packet.ray.dir_x[l] = p.dir_x[l];
        packet.ray.dir_y[l] = p.dir_y[l];
        packet.ray.dir_z[l] = p.dir_z[l];
        packet.ray.tfar[l] = p.tfar[l];
        packet.ray.mask[l] = 0xFFFFFFFFu;
        packet.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
        packet.hit.instID[0][l] = RTC_INVALID_GEOMETRY_ID;
    }
    if (p.occlusion) {
        occluded16_at(width, p.valid.data(), scene, context, packet.ray);
    } else {
        intersect16_at(width, p.valid.data(), scene, context, packet);
    }
}

void replay_single(const RecordedPacket& p, RTCScene scene, RTCIntersectContext* context) {
    for (std::size_t l = 0; l < kLanes; ++l) {
        if (p.valid[l] == 0) continue;
        RTCRayHit one = single_ray(p, l);
        if (p.occlusion) {
            rtcOccluded1(scene, context, &one.ray);
        } else {
            rtcIntersect1(scene, context, &one);
        }
    }
}

// The valid rays of packets [first, last) (one call of the renderer: same kind) as one stream.
void replay_stream(const RecordedPacket* first, const RecordedPacket* last, RTCScene scene,
                   RTCIntersectContext* context) {
    thread_local std::vector<RTCRayHit> stream;
    stream.clear();
    for (const RecordedPacket* p = first; p != last; ++p)
        for (std::size_t l = 0; l < kLanes; ++l)
            if (p->valid[l] != 0) stream.push_back(single_ray(*p, l));
    const auto n = static_cast<unsigned>(stream.size());
    if (first->occlusion) {
        rtcOccluded1M(scene, context, &stream.data()->ray, n, sizeof(RTCRayHit));
    } else {
        rtcIntersect1M(scene, context, stream.data(), n, sizeof(RTCRayHit));
    }
}

int replay_flags(const RecordedPacket& p, ReplayShape shape) {
    switch (shape) {
        case ReplayShape::kAsRecorded:
            return p.coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
        case ReplayShape::kStreams:
            return RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        case ReplayShape::kCoherentFirstHit:
            return p.occlusion && p.depth == 0 ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT
                                               : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
        default:
            return RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    }
}

}  // namespace

TileStats Renderer::trace_recorded(const RecordedRays& log, ReplayShape shape) const {
    const Impl& s = *impl_;
    s.check_ready();
    TileStats stats{log.ray_count()};
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    const RTCScene scene = s.geometry.root();
    const bool streams = shape == ReplayShape::kStreams || shape == ReplayShape::kIncoherentStreams;
    for (std::size_t i = 0; i < log.packets.size();) {
        const RecordedPacket& p = log.packets[i];
        context.flags = static_cast<RTCIntersectContextFlags>(replay_flags(p, shape));
        if (streams) {
            std::size_t j = i + 1;
            while (j < log.packets.size() && !log.packets[j].starts_call) ++j;
            replay_stream(&p, log.packets.data() + j, scene, &context);
            i = j;
            continue;
        }
        const bool packet = shape == ReplayShape::kAsRecorded ? p.packet : shape != ReplayShape::kSingleRays;
        if (packet) {
            replay_packet(p, s.packet_width(), scene, &context);
        } else {
            replay_single(p, scene, &context);
        }
        ++i;
    }
    return stats;
}

TileStats Renderer::trace_camera_rays(const PixelRect& rect) const {
    const Impl& s = *impl_;
    s.check_target(rect, nullptr);
    TileStats stats;
    Impl::for_each_block(rect, [&](const Block& block) {
        for (int sample = 0; sample < s.spp; ++sample) {
            RTCRayHit16 packet{};  // masked lanes stay zero (defined for tools like valgrind)
            std::array<PixelSampler, kLanes> rngs;
            s.fill_packet(block, sample, packet, rngs);
            s.intersect(block, packet);
            stats.rays += static_cast<std::uint64_t>(block.active);
        }
    });
    return stats;
}

}  // namespace mogao
