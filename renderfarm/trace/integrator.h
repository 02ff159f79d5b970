// SPDX-License-Identifier: Apache-2.0
// Light transport at a surface hit: next-event estimation of every light plus `max_bounces`
// indirect bounces, ended early by Russian roulette (below). Every estimator below is unbiased
// (consistent as samples grow); no light arrives without a visibility test.
//
// Per path vertex x with shading normal n, geometric normal ng (both facing the incoming ray),
// outgoing direction wo, BRDF f (shading.h, energy conserving):
//   directional:  f(wi) E cosθ                                   wi = to_light
//   point:        f(wi) I cosθ / d²                              (inverse-square law)
//   area:         (1/N) Σ f(wi) L cosθ cosθ_l A / d²            N = area_light_samples points
//                 on the parallelogram (pdf 1/A, area -> solid angle by cosθ_l/d²,
//                 PBRT 3rd ed. §14.2.2); one-sided: cosθ_l = n_l·(-wi) <= 0 contributes 0
//   environment:  (1/N) Σ π f(wo, w_k) L_env V(w_k),  N = max(1, ao_samples) cosine-weighted
//                 directions w_k (pdf cosθ/π), V = 1 if the ray escapes the scene: the Monte Carlo
//                 estimate of ∫ f L_env V cosθ dω (PBRT 4th ed. §13.1). ao_samples = 0 traces one
//                 ray too: the environment is never assumed unoccluded (inside a closed room no
//                 sky light arrives), and the whole BRDF, glossy lobe included, sees it.
// A light direction counts only if it is above both n and ng (no light leaks through the
// surface at smooth-shading terminators). Shadow rays are traced only for lights with
// cast_shadows; they end at 0.999 d for point and area lights.
// Bounces: wi cosine-weighted around n, throughput *= π f(wo, wi) (= f cosθ / pdf). With
// FrameContext::glossy_vndf, a glossy material's bounce instead picks the GGX lobe with
// probability p_g (shading.h, glossy_lobe_probability: the lobes' luminance shares) and reflects wo
// about a visible normal (Heitz, "Sampling the GGX Distribution of Visible Normals", JCGT 2018),
// else the cosine lobe; either way throughput *= f cosθ / p(wi) with the mixture's pdf
// p = (1 - p_g) cosθ/π + p_g G1(wo) D(h) / (4 cosθo): Veach's one-sample MIS with the balance
// heuristic (Veach 1997, §9.2.4), so whichever lobe dominates a direction carries it. The same
// p is the bounce pdf in the area-light MIS weights below. Matte materials (p_g = 0) draw and
// compute exactly what they did without it. Environment from the bounce (FrameContext::environment_from_bounce, with
// ao_samples <= 1): at a vertex a bounce follows, the environment gets no ray of its own; the bounce ray, if it
// escapes, adds throughput_after_bounce · L_env, that is β f cosθ / p(wi) L_env (divided by q where roulette kept
// it): a one-sample estimate of the same ∫ f L_env V cosθ dω with the bounce's pdf (for a matte surface the cosine,
// the pdf next-event estimation uses), so it is unbiased and saves one ray per such vertex (PBRT 4th ed.
// §13.1: any pdf that is non-zero where the integrand is gives an unbiased estimate). Lost bounces (below the surface,
// ended by roulette) lose its term, as unbiased as roulette itself. The last vertex, vertices with ao_samples > 1 and
// cache training paths keep next-event estimation. Otherwise a bounce ray that escapes contributes nothing: the
// environment (the only thing an escaping ray could see) is then counted by next-event estimation, so adding it
// again would double count it; area lights are not intersectable either (scene.h), so no emission is ever found by
// a bounce ray. Russian roulette (FrameContext::russian_roulette; Arvo & Kirk, "Particle Transport and Image
// Synthesis", SIGGRAPH 1990, §4; as PBRT 4th ed. §14.5.1 / pbrt-v4's PathIntegrator): the bounce leaving a vertex of
// depth >= kRouletteMinDepth (the camera ray's hit is depth 0, so the first bounce is always traced) survives with
// probability q = min(1, sqrt(max channel of the path throughput after the bounce)) (the square root as Cycles takes
// it: a gentler cut than q = max channel, which in a room lit mostly by interreflection raised the error per sample by
// more than it saved; docs/renderer.md, "Cheaper and better samples"), and a surviving path's throughput is divided by
// q. The expected value of every later term is unchanged (E[X/q · 1{u < q}] = E[X]), so the estimator stays unbiased;
// paths whose throughput has become small end early and save their bounce and next-event rays. A throughput >= 1 in
// every channel (albedo 1) is never rouletted. The decision draws a PixelSampler pair of its own only when q < 1, so a
// frame without roulette (or with q = 1 everywhere) draws the numbers it drew before. Random numbers: one PixelSampler
// pair (sobol.h) per light sample set, environment and bounce, so each is a stratified Owen-scrambled Sobol' net over
// the pixel's samples.
//
// Light selection (FrameContext::legacy_light_sampling = false; RendererOptions keeps the legacy
// estimator by default, renderer.h says why): the point, directional
// and area lights above are not each given a shadow ray; instead N = area_light_samples light
// samples per vertex each pick ONE light with the probabilities of light_selection.h and weight
// it by 1/p(light) (unbiased; PBRT 4th ed. §12.6 and §13.4). For area lights the point on the
// light is uniform (pdf 1/A) and, where a bounce follows (depth < max_bounces), combined with the
// bounce's cosine-sampled direction by multiple importance sampling with the power heuristic
// (Veach 1997, §9.2.4, β = 2; PBRT 4th ed. §13.4.1): a light sample at direction ω has weight
//   w_l = (N p_l)² / ((N p_l)² + p_b²),  p_l = p(light) d² / (cosθ_l A),  p_b = the bounce pdf
//   (cosθ / π, or the lobe mixture's above),
// and a bounce ray that reaches the front of an area light before any geometry adds
// throughput · L · w_b with w_b = p_b² / ((N p_l)² + p_b²) (so area lights are found by bounce
// rays in this mode; the weights of both strategies sum to 1 for every direction). Emission of
// a light whose cast_shadows is false is counted by a bounce ray whatever geometry lies in front,
// as its shadow rays are never traced. legacy_light_sampling = true is the estimator above
// (one ray per light, area_light_samples per area light, no MIS), kept for comparison.
//
// Secondary rays: every vertex turns its light, environment and bounce samples into a list of
// shadow queries (origin, direction, end, the radiance added if unoccluded) before any is traced.
// The single-ray path traces them with rtcOccluded1; the packet path (packet_integrator.h) traces
// the queries of a 4x4 pixel block together with rtcOccluded16, grouped per light, and its bounce
// rays with rtcIntersect16. Both draw the same random numbers and add the same terms in the same
// order, so they differ only where Embree's packet and single-ray kernels disagree on a hit.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "common/view_request.h"
#include "renderfarm/trace/light_set.h"
#include "renderfarm/trace/recorded_rays.h"
#include "renderfarm/trace/render_scene.h"
#include "renderfarm/trace/shading.h"
#include "renderfarm/trace/sobol.h"

namespace mogao {

struct FrameContext {
    const RenderScene* scene = nullptr;
    const LightSet* lights = nullptr;
    const std::vector<ShadingMaterial>* materials = nullptr;
    int max_bounces = 0;
    int ao_samples = 0;
    int area_light_samples = 1;
    bool legacy_light_sampling = false;  // one shadow ray per light (see above)
    int packet_width = 16;               // Embree packet width of the packet path (embree_packets.h)
    float cone_spread = 0.0f;            // radians: a camera sample's ray-cone spread (camera_cone_spread,
                                         // texture_lod.h); 0 filters no texture
    // Benchmark baseline only (RendererOptions::coherent_shadow_packets_baseline): the packet path's
    // light shadow packets traced with RTC_INTERSECT_CONTEXT_FLAG_COHERENT, as before the ray-flag
    // audit; every secondary ray is otherwise traced INCOHERENT (packet_integrator.h).
    bool coherent_shadow_packets = false;
    bool russian_roulette = false;  // end paths by Russian roulette (see above)
    bool glossy_vndf = false;       // glossy bounces from GGX visible normals (see above)
    // The radiance cache's training paths (cached_packet.h): at the first vertex the surface is
    // taken as white Lambertian, only the environment is sampled there and its bounce adds no area
    // emission, so a path estimates the white radiance of the cache's part of the light.
    bool cache_training = false;
    bool environment_from_bounce = false;  // the environment from escaping bounce rays (see above)
};

// Whether a vertex takes the environment from its bounce ray instead of next-event estimation (see above):
// FrameContext::environment_from_bounce, a bounce follows, one environment sample (ao_samples <= 1) and no
// cache training path (whose first vertex samples only the environment).
[[nodiscard]] inline bool environment_from_bounce(const FrameContext& frame, bool bounce_follows) {
    return frame.environment_from_bounce && bounce_follows && frame.ao_samples <= 1 && !frame.cache_training;
}

// The white Lambertian material of a cache training path's first vertex (albedo 1).
[[nodiscard]] ShadingMaterial white_lambert();

// The first path depth whose bounce may be ended by Russian roulette (depth 0 = the camera hit).
inline constexpr int kRouletteMinDepth = 1;

// One shadow ray and what it adds (already multiplied by the path throughput) when unoccluded.
struct ShadowQuery {
    Eigen::Vector3f origin;
    Eigen::Vector3f direction;  // unit
    float tfar = 0.0f;
    Eigen::Vector3f contribution;
    int group = 0;  // which light (index of light_selection.h) or environment (-1): packets group by it
};

// A path vertex ready for shading.
struct ShadingVertex {
    const SurfaceHit* hit = nullptr;
    ShadingMaterial material;  // with the hit's tint applied
    Eigen::Vector3f wo;
    Eigen::Vector3f origin;  // offset along the geometric normal (ray_offset.h)
};

[[nodiscard]] ShadingVertex make_vertex(const FrameContext& frame, const SurfaceHit& hit, const Eigen::Vector3f& wo);

// Which parts of next-event estimation direct_light_queries samples (the radiance cache splits
// them: cached_packet.h).
enum class DirectParts { kAll, kLightsOnly, kEnvironmentOnly };

// Appends the shadow queries of next-event estimation at `x` (lights, then environment), each
// contribution scaled by `throughput`; unshadowed light terms go straight into `unshadowed`.
void direct_light_queries(const FrameContext& frame, const ShadingVertex& x, const Eigen::Vector3f& throughput,
                          bool bounce_follows, PixelSampler& sampler, std::vector<ShadowQuery>& queries,
                          Eigen::Vector3f& unshadowed, DirectParts parts = DirectParts::kAll);

// The bounce of a vertex at path depth `depth`: direction and new throughput (already divided by
// the roulette's survival probability), or false when the path ends (below the surface, zero
// throughput, or ended by Russian roulette).
struct Bounce {
    Eigen::Vector3f direction;
    Eigen::Vector3f throughput;
};
[[nodiscard]] bool sample_bounce(const FrameContext& frame, const ShadingVertex& x, const Eigen::Vector3f& throughput,
                                 int depth, PixelSampler& sampler, Bounce& out);

// MIS-weighted area-light emission seen by a bounce ray from `x` along `dir` whose nearest
// geometry hit is at `t_hit` (infinity if it escapes); 0 in legacy mode. `throughput` is the
// path throughput after the bounce.
[[nodiscard]] Eigen::Vector3f bounce_emission(const FrameContext& frame, const ShadingVertex& x,
                                              const Eigen::Vector3f& dir, float t_hit,
                                              const Eigen::Vector3f& throughput);

// Radiance leaving `hit` toward the ray origin (wo = -ray direction, unit). `rays` is incremented
// for every shadow, occlusion and bounce ray traced. Single rays (rtcOccluded1/rtcIntersect1);
// `log` (benchmarks only, may be null) receives every ray traced.
[[nodiscard]] Eigen::Vector3f radiance_at(const FrameContext& frame, const SurfaceHit& hit, const Eigen::Vector3f& wo,
                                          PixelSampler& sampler, std::uint64_t& rays, RecordedRays* log = nullptr);

}  // namespace mogao
