// SPDX-License-Identifier: Apache-2.0
// The trace stage: renders linear radiance for a rect of a view request's frame with Embree.
//
// Usage: Renderer r(scene, options); per frame: r.begin_frame(request); then any number of
// r.render(rect, frame) calls, possibly concurrently from several threads on disjoint rects of
// the same frame buffer (render() is const and has no shared mutable state).
//
// Frame buffer: RgbFloatImage of exactly render_size() (= round(request.size * resolution_scale),
// view_validation.h); render() writes linear radiance (scene units, before exposure) only to the
// pixels inside `rect` and leaves every other pixel untouched. Camera rays that hit nothing see
// the summed environment radiance (the sky); integrator.h describes what a hit receives.
//
// Radiance cache: a request with radiance_cache set (the farm's moving frames) reads the world-space
// cache of earlier frames and trains it (cached_packet.h): its pixels then also depend on which
// frames this Renderer drew before (still bit-identical for any split of one frame into rects on
// one Renderer: a frame reads only what earlier frames committed, in a fixed order). Other frames
// are the unbiased path tracer below and never touch the cache. Animated lights (scene.h,
// LightAnimation) are evaluated at the request's scene_time_s; a frame whose lights differ from the
// previous frame's rebuilds them and empties the cache (what it learnt belongs to the old lights).
// A cached request with shading_one_in > 1 (view_request.h) shades only its pattern's pixels and the
// cache's training pixels; its other surface pixels get kUnshadedRadiance (their guides as usual).
//
// Determinism: a pixel's value depends only on (scene, request incl. seed and frame_id, x, y):
// camera rays are traced in 4x4 packets aligned to the global image grid (x0 % 4 == 0,
// y0 % 4 == 0), lanes outside rect or image masked off, one packet per sample index; all random
// numbers are hashes of (seed, frame_id, x, y, sample, dimension) (rng.h, sobol.h), the sub-pixel
// position at every spp included (RendererOptions::jitter_one_spp). So any split of the
// frame into rects (e.g. across MPI ranks) reproduces the single-rect frame bit for bit.
//
// Lifetime: the Scene must outlive the Renderer (mesh indices and normals are shared, not copied).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "common/image.h"
#include "common/pixel_rect.h"
#include "common/view_request.h"
#include "renderfarm/scene/scene.h"
#include "renderfarm/trace/guide_buffers.h"
#include "renderfarm/trace/radiance_cache.h"
#include "renderfarm/trace/recorded_rays.h"
#include "renderfarm/trace/render_scene.h"

namespace mogao {

struct RendererOptions {
    // rtcNewDevice configuration, e.g. "threads=1" to build BVHs on one thread; "" = Embree default
    // (all hardware threads for BVH builds; rendering itself runs on the caller's threads).
    std::string embree_config;
    // Rebase the world on the eye every frame (render_scene.h). Only benchmarks and the precision
    // test turn this off, to measure what it buys.
    bool rebase_on_eye = true;
    // How the BVHs are built (render_scene.h; fixed at construction like embree_config).
    BvhOptions bvh = {};
    // The path speed-ups, each of which can be turned off so a benchmark times today's path and
    // the new one in one run (docs/renderer.md, "Performance"). None changes what the renderer
    // converges to; legacy_light_sampling = false changes the noise (a different unbiased
    // estimator), the others give the same image up to Embree's packet and single-ray kernels
    // disagreeing on a hit.
    // One shadow ray per light per sample instead of one light chosen per sample (integrator.h).
    // On by default: light selection is unbiased but, with an occlusion-blind estimate, noisier
    // per sample where a strong light is mostly shadowed (the grotto's sun); the benchmark prints
    // its PSNR and time against this path (docs/renderer.md).
    bool legacy_light_sampling = true;
    // Shadow, environment and bounce rays of a 4x4 block traced as 16-wide packets
    // (packet_integrator.h) instead of one rtcOccluded1 / rtcIntersect1 at a time.
    bool packet_secondary_rays = true;
    // Cylinder camera at 1 spp: the per-column sin/cos of the screen angle computed once per frame
    // (camera.h, CylinderColumns) instead of per ray; bit-identical rays.
    bool camera_column_table = true;
    // Camera and secondary packets traced at the CPU's native width (embree_packets.h: two
    // rtcIntersect8 / rtcOccluded8 halves on AVX2, where Embree would run a 16-wide call ray by ray).
    bool native_packet_width = true;
    // Russian roulette ends paths whose throughput has become small (integrator.h: survival
    // probability = the square root of the throughput's largest channel, from the second bounce on; unbiased). Off
    // traces every path to max_bounces, as before; tests and benchmarks compare both.
    bool russian_roulette = true;
    // At spp = 1, the pixel's one sample at an Owen-scrambled Sobol' point (sobol.h; a fresh
    // position per seed and frame_id, so passes accumulated over frame ids converge to the pixel's
    // area average: antialiased edges). Off samples the pixel centre (x + 0.5, y + 0.5), as before,
    // which never converges to the area average. spp > 1 always takes the pixel's Sobol' points.
    bool jitter_one_spp = true;
    // A radiance-cache frame (ViewRequest::radiance_cache) of one sample per pixel takes it at the
    // pixel centre even with jitter_one_spp: its first camera hits are then the guide pass's
    // (guide_pass.h), so the farm takes the denoiser's guides from them and traces no guide ray
    // (samples_pixel_centres()). Such frames are biased and never accumulated; their cells'
    // jittered lookups and the temporal accumulation's reprojection already vary them from frame to
    // frame. On: jittered like any 1-spp frame. The serve bench measures both (docs/renderer.md).
    bool jitter_cached_one_spp = false;
    // Glossy materials' bounces drawn from the GGX visible normals (Heitz 2018) mixed with the
    // cosine lobe by one-sample MIS (integrator.h); off: every bounce cosine-sampled, as before.
    // Matte materials are unaffected either way.
    bool glossy_vndf_sampling = true;
    // Where a bounce follows a path vertex, the environment is taken from that bounce ray when it
    // escapes (integrator.h, "Environment from the bounce") instead of from an occlusion ray of its
    // own: one ray fewer per vertex, unbiased. Off: the environment's own ray at every vertex, as before.
    bool environment_from_bounce = true;
    // The radiance cache of frames whose request asks for it (ViewRequest::radiance_cache;
    // radiance_cache.h, cached_packet.h). Frames that do not ask neither read nor train it.
    RadianceCacheOptions radiance_cache = {};
    // Benchmark baseline only, not a setting: traces the packet path's light shadow packets with
    // RTC_INTERSECT_CONTEXT_FLAG_COHERENT, the flag they had before the ray-flag audit (Embree
    // reserves it for coherent rays such as camera rays; it made them about twice as slow). The
    // same pixels either way (RendererRayFlags test); mogao_bench_render times both in one run.
    bool coherent_shadow_packets_baseline = false;
};

// How Renderer::trace_recorded hands a recorded log to Embree (benchmarks only). "Packets" are
// 16-lane packets at the native width (embree_packets.h); a "call" is one vertex of one 4x4 block
// (its shadow queries, or its bounce rays: RecordedPacket::starts_call). Embree 3 traces a
// COHERENT stream by regrouping it into packets, an INCOHERENT one ray by ray (Embree 3 API,
// rtcIntersect1M and RTCIntersectContextFlags).
enum class ReplayShape {
    kAsRecorded,         // each packet in its recorded shape and context flag
    kIncoherentPackets,  // every packet as a packet, INCOHERENT
    kCoherentFirstHit,   // packets; COHERENT for the shadow rays of the camera ray's hit, INCOHERENT after
    kSingleRays,         // every ray alone (rtcOccluded1 / rtcIntersect1), INCOHERENT
    kStreams,            // each call as one rtcOccluded1M / rtcIntersect1M stream, COHERENT
    kIncoherentStreams,  // each call as one stream, INCOHERENT
};

struct RadianceCacheStats {
    std::size_t cells = 0;      // cells holding an estimate
    std::uint64_t dropped = 0;  // estimates dropped: non-finite, or no free slot (radiance_cache.h)
};

struct TileStats {
    std::uint64_t rays = 0;  // every ray traced: camera, shadow, ambient-occlusion and bounce
};

class Renderer {
public:
    // Builds the Embree BVHs (seconds for millions of triangles). Throws std::invalid_argument for
    // an inconsistent scene (bad indices, degenerate lights, ...), std::runtime_error for Embree.
    explicit Renderer(const Scene& scene, const RendererOptions& options = {});
    ~Renderer();
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;
    Renderer(Renderer&&) noexcept;
    Renderer& operator=(Renderer&&) noexcept;

    // Replaces the path switches (legacy_light_sampling, packet_secondary_rays, camera_column_table,
    // native_packet_width, russian_roulette, jitter_one_spp, jitter_cached_one_spp, glossy_vndf_sampling,
    // environment_from_bounce) from the next begin_frame on, so a benchmark times both paths on one BVH;
    // embree_config and rebase_on_eye keep their constructor values. Not thread-safe.
    void set_path_options(const RendererOptions& options);

    // Validates the request (std::invalid_argument naming the field and limit, see
    // view_validation.h), rebases the world on the eye and prepares cameras and lights. Not
    // thread-safe: no render() may run concurrently. On throw, the previous frame stays current.
    void begin_frame(const ViewRequest& request);

    // Size of the frame buffer for the current frame. Throws std::logic_error before begin_frame.
    [[nodiscard]] ImageSize render_size() const;

    // Whether the current frame's camera rays go through the pixel centres (one sample, not
    // jittered): its first hits, the guides render() writes, are then the guide pass's. Throws
    // std::logic_error before begin_frame.
    [[nodiscard]] bool samples_pixel_centres() const;

    // Renders the pixels of `rect` into `frame`. Throws std::invalid_argument if rect is not inside
    // [0, render_size()) or frame.size != render_size(), std::logic_error before begin_frame.
    TileStats render(const PixelRect& rect, RgbFloatImage& frame) const;

    // The same pixels into a window of the frame: pixel (x, y) goes to
    // window.at(x - origin_x, y - origin_y), so a render rank holds only its share (a tile) instead
    // of a whole frame. The values are bit-identical to render()'s. Throws std::invalid_argument if
    // rect is not inside [0, render_size()) or not inside the window placed at the origin.
    TileStats render(const PixelRect& rect, RgbFloatImage& window, int origin_x, int origin_y) const;

    // The same pixels, and the first camera hit of each pixel's first sample into `guides`, a window
    // of the same place and size (guide_buffers.h: hit, albedo = material albedo x the hit's tint,
    // the shading normal facing the ray, depth = distance along the unit camera ray in metres, as
    // the guide pass resolves them), so a frame that needs the denoiser's guides gets them from
    // rays it traces anyway instead of a second primary ray per pixel. Radiance bit-identical to
    // render()'s; the guides are the same for any split of the frame. Throws std::invalid_argument
    // as above, or if guides.size != window.size or its buffers do not hold W*H (hit, depth) and
    // W*H*3 (albedo, normal) values.
    TileStats render(const PixelRect& rect, RgbFloatImage& window, int origin_x, int origin_y,
                     GuideBuffers& guides) const;

    // The radiance cache (radiance_cache.h): emptied (a benchmark's cold start), and its size.
    // Neither may run concurrently with render() or begin_frame().
    void clear_radiance_cache();
    // Merges the training estimates of the frames rendered so far into the radiance cache now
    // instead of at the next begin_frame(): a render rank calls it once its tiles are sent, so the
    // merge runs while the admin composites, filters and encodes, not before the next frame's tiles.
    // The cache's content is the same either way. Not concurrently with render() or begin_frame().
    void commit_radiance_cache();
    [[nodiscard]] RadianceCacheStats radiance_cache_stats() const;

    // Benchmark baseline: generates and intersects exactly the camera ray packets render() would
    // (same grid, masks and samples) with rtcIntersect16, without any shading or secondary rays.
    TileStats trace_camera_rays(const PixelRect& rect) const;

    // Benchmark support: render() that also keeps every secondary ray it traced, and raw Embree
    // tracing such a log without any shading: as traced (same packets or single rays, same context
    // flags) or in another shape (ReplayShape), to measure which shape traces those rays fastest.
    TileStats render_recording(const PixelRect& rect, RgbFloatImage& frame, RecordedRays& log) const;
    TileStats trace_recorded(const RecordedRays& log, ReplayShape shape = ReplayShape::kAsRecorded) const;

    // The renderer's Embree geometry, rebased by begin_frame() on the current frame's eye (or not
    // at all when rebase_on_eye is off), for passes that trace the same frame's primary hits
    // without a second BVH (the denoiser's guide pass, renderfarm/denoise/guide_pass.h). Lives as
    // long as the Renderer; the same thread-safety as render(): const use only between frames'
    // begin_frame() calls.
    [[nodiscard]] const RenderScene& render_scene() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace mogao
