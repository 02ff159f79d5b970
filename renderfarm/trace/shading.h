// SPDX-License-Identifier: Apache-2.0
// Surface reflectance: Lambert diffuse plus an optional GGX microfacet glossy lobe, mixed so that
// the BRDF never reflects more light than it receives.
//
//   f(wo, wi) = (1 - k_s) · a / π  +  k_s · D(h) G2(wo, wi) / (4 cosθo cosθi)     (per channel)
//
// a = albedo (diffuse reflectance), k_s = specular (the fraction of light the glossy layer takes),
// h = normalize(wi + wo), cosθ = n·w.
//   Lambert: PBRT 4th ed. §9.2 (directional albedo a, exactly).
//   GGX (Trowbridge-Reitz) distribution D(h) = α² / (π (cos²θh (α² - 1) + 1)²) and the
//   height-correlated Smith masking-shadowing G2 = 1 / (1 + Λ(wo) + Λ(wi)),
//   Λ(w) = (√(1 + α² tan²θ) - 1) / 2: PBRT 4th ed. §9.6.1-§9.6.3 (Walter et al., "Microfacet Models
//   for Refraction through Rough Surfaces", EGSR 2007; Heitz, "Understanding the Masking-Shadowing
//   Function", JCGT 3(2), 2014). Its directional albedo ∫ f cosθi dωi is <= 1 for every wo (the
//   energy masking removes is lost, not created: single scattering only), so the mix's albedo is
//   <= (1 - k_s) a + k_s <= 1 per channel: energy conserving for any valid material.
//   No Fresnel term (a constant reflectance k_s, as for a dielectric coat seen away from grazing).
//   Roughness from the scene's Blinn-Phong exponent s: α = √(2 / (s + 2)) (Walter et al. 2007,
//   §5.2, the exponent <-> roughness correspondence); s = 40 gives α = 0.218.
// Directions are unit vectors pointing away from the surface; the caller multiplies by cosθi.
// The glossy term is only evaluated for materials whose specular is non-zero
// (ShadingMaterial::glossy), so matte scenes never pay for it.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Core>

#include "renderfarm/scene/scene.h"

namespace mogao {

struct ShadingMaterial {
    Eigen::Vector3f albedo = Eigen::Vector3f::Zero();    // diffuse reflectance a (before the mix)
    Eigen::Vector3f diffuse = Eigen::Vector3f::Zero();   // (1 - k_s) a / π
    Eigen::Vector3f specular = Eigen::Vector3f::Zero();  // k_s
    float alpha = 1.0f;                                  // GGX roughness
    bool glossy = false;                                 // specular non-zero
};

// GGX roughness for a Blinn-Phong exponent (Walter et al. 2007, §5.2).
[[nodiscard]] inline float ggx_alpha_from_shininess(float shininess) {
    return std::sqrt(2.0f / (std::max(shininess, 0.0f) + 2.0f));
}

[[nodiscard]] inline ShadingMaterial make_shading_material(const Material& m) {
    constexpr float kInvPi = std::numbers::inv_pi_v<float>;
    ShadingMaterial s;
    s.albedo = m.albedo;
    s.glossy = m.specular.maxCoeff() > 0.0f;
    s.specular = m.specular;
    s.diffuse = m.albedo.cwiseProduct(Eigen::Vector3f::Ones() - m.specular) * kInvPi;
    s.alpha = ggx_alpha_from_shininess(m.shininess);
    return s;
}

// The material with its albedo multiplied by a surface's tint (vertex colour x texture, linear
// RGB in [0, 1]); the glossy layer keeps its k_s (a coat over the painted surface).
[[nodiscard]] inline ShadingMaterial tinted_material(const ShadingMaterial& m, const Eigen::Vector3f& tint) {
    ShadingMaterial s = m;
    s.albedo = m.albedo.cwiseProduct(tint);
    s.diffuse = m.diffuse.cwiseProduct(tint);
    return s;
}

// GGX distribution D(cosθh) for roughness α.
[[nodiscard]] inline float ggx_d(float cos_h, float alpha) {
    const float a2 = alpha * alpha;
    const float d = cos_h * cos_h * (a2 - 1.0f) + 1.0f;
    return a2 / (std::numbers::pi_v<float> * d * d);
}

// Smith Λ for GGX at a direction with cosθ = cos_t (> 0).
[[nodiscard]] inline float ggx_lambda(float cos_t, float alpha) {
    const float cos2 = cos_t * cos_t;
    const float tan2 = std::max(0.0f, 1.0f - cos2) / cos2;
    return 0.5f * (std::sqrt(1.0f + alpha * alpha * tan2) - 1.0f);
}

// The glossy lobe without k_s: D G2 / (4 cosθo cosθi); 0 when either direction is below n.
[[nodiscard]] inline float ggx_lobe(const Eigen::Vector3f& n, const Eigen::Vector3f& wo, const Eigen::Vector3f& wi,
                                    float alpha) {
    const float cos_o = n.dot(wo);
    const float cos_i = n.dot(wi);
    if (!(cos_o > 0.0f) || !(cos_i > 0.0f)) return 0.0f;
    const Eigen::Vector3f half = (wi + wo).normalized();
    const float g2 = 1.0f / (1.0f + ggx_lambda(cos_o, alpha) + ggx_lambda(cos_i, alpha));
    return ggx_d(std::max(0.0f, n.dot(half)), alpha) * g2 / (4.0f * cos_o * cos_i);
}

// BRDF value (per channel) for unit n, wo, wi.
[[nodiscard]] inline Eigen::Vector3f eval_brdf(const ShadingMaterial& m, const Eigen::Vector3f& n,
                                               const Eigen::Vector3f& wo, const Eigen::Vector3f& wi) {
    if (!m.glossy) return m.diffuse;
    return m.diffuse + m.specular * ggx_lobe(n, wo, wi, m.alpha);
}

// Smith G1 = 1 / (1 + Λ) for GGX at a direction with cosθ = cos_t (> 0).
[[nodiscard]] inline float ggx_g1(float cos_t, float alpha) { return 1.0f / (1.0f + ggx_lambda(cos_t, alpha)); }

// Solid-angle pdf of wi = reflect(wo, h) with h drawn from the visible normals of wo
// (sampling.h, ggx_visible_normal): D_wo(h) / (4 wo·h) = G1(wo) D(h) / (4 cosθo) (Heitz 2018, §3;
// PBRT 4th ed. §9.6.4). 0 when either direction is below n.
[[nodiscard]] inline float ggx_reflection_pdf(const Eigen::Vector3f& n, const Eigen::Vector3f& wo,
                                              const Eigen::Vector3f& wi, float alpha) {
    const float cos_o = n.dot(wo);
    const float cos_i = n.dot(wi);
    if (!(cos_o > 0.0f) || !(cos_i > 0.0f)) return 0.0f;
    const Eigen::Vector3f half = (wi + wo).normalized();
    return ggx_g1(cos_o, alpha) * ggx_d(std::max(0.0f, n.dot(half)), alpha) / (4.0f * cos_o);
}

// Probability of sampling the glossy lobe rather than the cosine lobe: the lobes' shares of the
// reflected light, by luminance (Rec. 709 weights) of k_s against (1 - k_s) a. 0 for matte.
[[nodiscard]] inline float glossy_lobe_probability(const ShadingMaterial& m) {
    if (!m.glossy) return 0.0f;
    const Eigen::Vector3f w(0.2126f, 0.7152f, 0.0722f);
    const float glossy = w.dot(m.specular);
    const float diffuse = w.dot(m.diffuse) * std::numbers::pi_v<float>;
    return glossy + diffuse > 0.0f ? glossy / (glossy + diffuse) : 0.0f;
}

}  // namespace mogao
