// SPDX-License-Identifier: Apache-2.0
// Sampling helpers (float, unit vectors). Formulas from Pharr, Jakob, Humphreys, "Physically
// Based Rendering", 3rd ed. (PBRT): §13.6.2 concentric disk mapping (Shirley & Chiu), §13.6.3
// cosine-weighted hemisphere by Malley's method (pdf = cosθ/π); orthonormal basis from one vector
// after Duff et al., "Building an Orthonormal Basis, Revisited", JCGT 6(1), 2017; GGX visible
// normals after Heitz, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4), 2018.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Core>

namespace mogao {

// Tangent frame (t, b, n) around a unit vector n; branchless, no normalisation needed.
struct Frame {
    Eigen::Vector3f t, b, n;
    explicit Frame(const Eigen::Vector3f& normal) : n(normal) {
        const float sign = std::copysign(1.0f, n.z());
        const float a = -1.0f / (sign + n.z());
        const float c = n.x() * n.y() * a;
        t = Eigen::Vector3f(1.0f + sign * n.x() * n.x() * a, sign * c, -sign * n.x());
        b = Eigen::Vector3f(c, sign + n.y() * n.y() * a, -n.y());
    }
    [[nodiscard]] Eigen::Vector3f to_world(const Eigen::Vector3f& v) const { return t * v.x() + b * v.y() + n * v.z(); }
};

// Concentric mapping of [0,1)² onto the unit disk (area-preserving, low distortion).
[[nodiscard]] inline Eigen::Vector2f concentric_disk(float u1, float u2) {
    const float ox = 2.0f * u1 - 1.0f;
    const float oy = 2.0f * u2 - 1.0f;
    if (ox == 0.0f && oy == 0.0f) return {0.0f, 0.0f};
    constexpr float kPiOver4 = std::numbers::pi_v<float> / 4.0f;
    float r = 0.0f;
    float theta = 0.0f;
    if (std::fabs(ox) > std::fabs(oy)) {
        r = ox;
        theta = kPiOver4 * (oy / ox);
    } else {
        r = oy;
        theta = 2.0f * kPiOver4 - kPiOver4 * (ox / oy);
    }
    return {r * std::cos(theta), r * std::sin(theta)};
}

// Cosine-weighted direction on the hemisphere around frame.n; pdf = cosθ/π.
[[nodiscard]] inline Eigen::Vector3f cosine_hemisphere(const Frame& frame, float u1, float u2) {
    const Eigen::Vector2f d = concentric_disk(u1, u2);
    const float z = std::sqrt(std::max(0.0f, 1.0f - d.squaredNorm()));
    return frame.to_world(Eigen::Vector3f(d.x(), d.y(), z));
}

// A GGX microfacet normal seen from wo, in the local frame (z = the surface normal, wo.z() > 0):
// distributed as D_wo(h) = G1(wo) max(0, wo·h) D(h) / cosθo (Heitz 2018, listing 1, isotropic α:
// stretch wo, sample the projected hemisphere of the stretched view, unstretch). The reflected
// direction wi = 2 (wo·h) h - wo then has pdf G1(wo) D(h) / (4 cosθo) (shading.h).
[[nodiscard]] inline Eigen::Vector3f ggx_visible_normal(const Eigen::Vector3f& wo, float alpha, float u1, float u2) {
    const Eigen::Vector3f vh = Eigen::Vector3f(alpha * wo.x(), alpha * wo.y(), wo.z()).normalized();
    const float lensq = vh.x() * vh.x() + vh.y() * vh.y();
    const Eigen::Vector3f t1 = lensq > 0.0f ? Eigen::Vector3f(Eigen::Vector3f(-vh.y(), vh.x(), 0.0f) / std::sqrt(lensq))
                                            : Eigen::Vector3f(Eigen::Vector3f::UnitX());
    const Eigen::Vector3f t2 = vh.cross(t1);
    const float r = std::sqrt(u1);
    const float phi = 2.0f * std::numbers::pi_v<float> * u2;
    const float p1 = r * std::cos(phi);
    const float s = 0.5f * (1.0f + vh.z());
    const float p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * r * std::sin(phi);
    const Eigen::Vector3f nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
    return Eigen::Vector3f(alpha * nh.x(), alpha * nh.y(), std::max(1e-6f, nh.z())).normalized();
}

}  // namespace mogao
