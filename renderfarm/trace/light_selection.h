// SPDX-License-Identifier: Apache-2.0
// Choosing which light a shadow ray samples: one light per light sample, picked with a
// probability proportional to an estimate of its contribution at the shading point, instead of
// one shadow ray per light (PBRT 4th ed. §12.6, "Light Sampling": power- and spatially-aware light
// samplers; the estimator f L cosθ / (p(light) p(ω | light)) stays unbiased for any p(light) that
// is non-zero wherever a light can contribute, §13.4.4 and Veach 1997 §9.2.2).
//
// Estimate per light (luminance Y of its power, Rec. 709 weights; n = shading normal, x = point):
//   directional: Y(E) max(0, n·l)                              (irradiance, no fall-off)
//   point:       Y(I) max(0, n·ω) / max(d², d_min²)            (inverse-square law)
//   area:        Y(L) A max(0, cosθ_l) / max(d², A)            (to the centre; the area floor keeps
//                                                              a point next to a big light finite)
// Probability: p_i = (1 - α) e_i / Σe + α / n with α = kUniformShare, so every light keeps
// p_i >= α/n > 0 (a light the estimate misjudges, e.g. an area light whose centre is below the
// horizon but whose corner is not, is still sampled: no bias, only variance). All estimates 0:
// uniform. Lights are indexed directional first, then point, then area (LightSet order).
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "renderfarm/trace/light_set.h"

namespace mogao {

inline constexpr float kUniformShare = 0.1f;     // α above
inline constexpr int kMaxSelectableLights = 32;  // lights beyond this: the legacy one-ray-per-light path

// The probabilities of one shading point.
struct LightSelection {
    int count = 0;
    float pdf[kMaxSelectableLights] = {};  // p_i
    float cdf[kMaxSelectableLights] = {};  // Σ_{j<=i} p_j (cdf[count - 1] forced to 1)

    // Index i with cdf[i-1] <= u < cdf[i]; `u` is remapped to [0, 1) inside the chosen interval,
    // so the same number can be reused for the position on the light (PBRT 4th ed. §A.1,
    // SampleDiscrete's uRemapped).
    [[nodiscard]] int sample(float& u) const;
};

[[nodiscard]] inline int selectable_light_count(const LightSet& lights) {
    return static_cast<int>(lights.directional.size() + lights.point.size() + lights.area.size());
}

// Estimates of the header comment at point `position` with shading normal `normal` (unit).
[[nodiscard]] LightSelection select_lights(const LightSet& lights, const Eigen::Vector3f& position,
                                           const Eigen::Vector3f& normal);

// Rec. 709 luminance.
[[nodiscard]] inline float luminance(const Eigen::Vector3f& c) {
    return 0.2126f * c.x() + 0.7152f * c.y() + 0.0722f * c.z();
}

}  // namespace mogao
