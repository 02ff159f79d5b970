// SPDX-License-Identifier: Apache-2.0
// Surface reflectance: Lambert diffuse plus an optional normalised Blinn-Phong glossy lobe.
//
//   f(wi, wo) = albedo / π  +  specular · (s + 2) / (2π) · max(0, n·h)^s,   h = normalize(wi + wo)
//
// Lambert: PBRT 3rd ed. §8.3. The glossy term uses the normalised Blinn-Phong distribution
// D(h) = (s+2)/(2π) (n·h)^s (Akenine-Möller et al., "Real-Time Rendering", 4th ed., §9.8.1,
// after Blinn 1977), used directly as the lobe. Directions are unit vectors pointing away from the
// surface; the caller multiplies by cosθ_i = n·wi. The glossy term is only evaluated for materials
// whose specular is non-zero (ShadingMaterial::glossy), so matte scenes never pay for it.
#pragma once

#include <cmath>
#include <numbers>

#include <Eigen/Core>

#include "renderfarm/scene/scene.h"

namespace mogao {

struct ShadingMaterial {
    Eigen::Vector3f albedo = Eigen::Vector3f::Zero();          // diffuse reflectance
    Eigen::Vector3f diffuse = Eigen::Vector3f::Zero();         // albedo / π
    Eigen::Vector3f glossy_scale = Eigen::Vector3f::Zero();    // specular · (s+2)/(2π)
    float shininess = 0.0f;
    bool glossy = false;                                        // specular non-zero
};

[[nodiscard]] inline ShadingMaterial make_shading_material(const Material& m) {
    constexpr float kInvPi = std::numbers::inv_pi_v<float>;
    ShadingMaterial s;
    s.albedo = m.albedo;
    s.diffuse = m.albedo * kInvPi;
    s.glossy = m.specular.maxCoeff() > 0.0f;
    s.shininess = m.shininess;
    s.glossy_scale = m.specular * ((m.shininess + 2.0f) * 0.5f * kInvPi);
    return s;
}

// BRDF value (per channel) for unit n, wo, wi on the same side.
[[nodiscard]] inline Eigen::Vector3f eval_brdf(const ShadingMaterial& m, const Eigen::Vector3f& n,
                                               const Eigen::Vector3f& wo, const Eigen::Vector3f& wi) {
    if (!m.glossy) return m.diffuse;
    const Eigen::Vector3f half = wi + wo;
    const float length = half.norm();
    if (!(length > 0.0f)) return m.diffuse;
    const float cos_h = std::max(0.0f, n.dot(half) / length);
    return m.diffuse + m.glossy_scale * std::pow(cos_h, m.shininess);
}

}  // namespace mogao
