// SPDX-License-Identifier: Apache-2.0
// Light transport at a surface hit: next-event estimation of every light plus `max_bounces`
// indirect bounces (a path tracer without Russian roulette). Every estimator below is unbiased
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
// Bounces: wi cosine-weighted around n, throughput *= π f(wo, wi) (= f cosθ / pdf). A bounce
// ray that escapes contributes nothing: the environment (the only thing an escaping ray could
// see) is already counted by next-event estimation at every vertex, so adding it again would
// double count it; area lights are not intersectable either (scene.h), so no emission is ever
// found by a bounce ray.
// Random numbers: one PixelSampler pair (sobol.h) per light sample set, environment and bounce,
// so each is a stratified Owen-scrambled Sobol' net over the pixel's samples.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "common/view_request.h"
#include "renderfarm/trace/light_set.h"
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
};

// Radiance leaving `hit` toward the ray origin (wo = -ray direction, unit). `rays` is incremented
// for every shadow, occlusion and bounce ray traced.
[[nodiscard]] Eigen::Vector3f radiance_at(const FrameContext& frame, const SurfaceHit& hit, const Eigen::Vector3f& wo,
                                          PixelSampler& sampler, std::uint64_t& rays);

}  // namespace mogao
