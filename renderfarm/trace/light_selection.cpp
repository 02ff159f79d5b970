// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/trace/light_selection.h"

#include <algorithm>
#include <cmath>

namespace mogao {
namespace {

constexpr float kMinPointDistance2 = 1e-4f;  // d_min = 1 cm: a point light on the surface stays finite

}  // namespace

int LightSelection::sample(float& u) const {
    int i = 0;
    while (i < count - 1 && u >= cdf[i]) ++i;
    const float lo = i == 0 ? 0.0f : cdf[i - 1];
    const float width = pdf[i];
    u = width > 0.0f ? std::min((u - lo) / width, 0x1.fffffep-1f) : 0.0f;
    u = std::max(u, 0.0f);
    return i;
}

LightSelection select_lights(const LightSet& lights, const Eigen::Vector3f& position, const Eigen::Vector3f& normal) {
    LightSelection s;
    s.count = selectable_light_count(lights);
    float estimate[kMaxSelectableLights] = {};
    int i = 0;
    for (const PreparedDirectional& l : lights.directional) {
        estimate[i++] = luminance(l.irradiance) * std::max(0.0f, normal.dot(l.to_light));
    }
    for (const PreparedPoint& l : lights.point) {
        const Eigen::Vector3f to_light = l.position - position;
        const float d2 = std::max(to_light.squaredNorm(), kMinPointDistance2);
        estimate[i++] = luminance(l.intensity) * std::max(0.0f, normal.dot(to_light)) / (d2 * std::sqrt(d2));
    }
    for (const PreparedArea& l : lights.area) {
        const Eigen::Vector3f to_centre = l.corner + 0.5f * (l.edge_u + l.edge_v) - position;
        const float d2 = to_centre.squaredNorm();
        const float cos_light = d2 > 0.0f ? std::max(0.0f, -l.normal.dot(to_centre) / std::sqrt(d2)) : 1.0f;
        estimate[i++] = luminance(l.radiance) * l.area * cos_light / std::max(d2, l.area);
    }
    float total = 0.0f;
    for (int k = 0; k < s.count; ++k) total += std::isfinite(estimate[k]) ? std::max(estimate[k], 0.0f) : 0.0f;
    const float uniform = 1.0f / static_cast<float>(std::max(s.count, 1));
    float running = 0.0f;
    for (int k = 0; k < s.count; ++k) {
        const float e = std::isfinite(estimate[k]) ? std::max(estimate[k], 0.0f) : 0.0f;
        s.pdf[k] = total > 0.0f ? (1.0f - kUniformShare) * e / total + kUniformShare * uniform : uniform;
        running += s.pdf[k];
        s.cdf[k] = running;
    }
    if (s.count > 0) s.cdf[s.count - 1] = 1.0f;
    return s;
}

}  // namespace mogao
