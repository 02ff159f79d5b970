// SPDX-License-Identifier: Apache-2.0
// Light transport at a surface hit: next-event estimation of every light plus `max_bounces`
// indirect diffuse bounces (a path tracer without Russian roulette).
//
// Per path vertex x with shading normal n, geometric normal ng (both facing the incoming ray),
// outgoing direction wo, BRDF f (shading.h):
//   directional:  f(wi) E cosθ                                   wi = to_light
//   point:        f(wi) I cosθ / d²                              (inverse-square law)
//   area:         (1/N) Σ f(wi) L cosθ cosθ_l A / d²            N = area_light_samples points
//                 uniform on the parallelogram (pdf 1/A, area -> solid angle by cosθ_l/d²,
//                 PBRT 3rd ed. §14.2.2); one-sided: cosθ_l = n_l·(-wi) <= 0 contributes 0
//   environment:  albedo L_env · V,  V = fraction of ao_samples cosine-weighted rays that escape
//                 (Monte Carlo of ∫ albedo/π L_env V cosθ dω with pdf cosθ/π); ao_samples = 0
//                 uses V = 1 (unoccluded). Only the diffuse term sees the environment.
// A light direction counts only if it is above both n and ng (no light leaks through the
// surface at smooth-shading terminators). Shadow rays are traced only for lights with
// cast_shadows; they end at 0.999 d for point and area lights.
// Bounces: wi cosine-weighted around n, throughput *= albedo (f cosθ / pdf for Lambert). A bounce
// ray that escapes contributes nothing: the environment (the only thing an escaping ray could
// see) is already counted by next-event estimation at every vertex, so adding it again would
// double count it; area lights are not intersectable either (scene.h), so no emission is ever
// found by a bounce ray.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "renderfarm/trace/light_set.h"
#include "renderfarm/trace/render_scene.h"
#include "renderfarm/trace/rng.h"
#include "renderfarm/trace/shading.h"
#include "common/view_request.h"

namespace mogao {

struct FrameContext {
    const RenderScene* scene = nullptr;
    const LightSet* lights = nullptr;
    const std::vector<ShadingMaterial>* materials = nullptr;
    int max_bounces = 0;
    int ao_samples = 0;
    int area_light_samples = 1;
};

// Radiance leaving `hit` toward the ray origin (wo = -ray direction, unit). `rays` is incremented
// for every shadow, occlusion and bounce ray traced.
[[nodiscard]] Eigen::Vector3f radiance_at(const FrameContext& frame, const SurfaceHit& hit, const Eigen::Vector3f& wo,
                                          PixelRng& rng, std::uint64_t& rays);

}  // namespace mogao
