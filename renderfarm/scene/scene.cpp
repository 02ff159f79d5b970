// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/scene/scene.h"

#include <algorithm>
#include <cmath>

namespace mogao {

float LightAnimation::scale_at(double time_s) const {
    if (scale.empty()) return 1.f;
    const double t = std::isfinite(time_s) ? std::max(time_s, 0.0) : 0.0;  // a NaN must not index
    const double step = std::floor(t / std::max(step_s, 1e-9));
    return scale[static_cast<std::size_t>(std::fmod(step, static_cast<double>(scale.size())))];
}

float light_scale(const Scene& scene, LightKind kind, std::size_t index, double time_s) {
    for (const AnimatedLight& a : scene.animated_lights) {
        if (a.kind == kind && a.index == index) return a.animation.scale_at(time_s);
    }
    return 1.f;
}

std::vector<float> lighting_state(const Scene& scene, double time_s) {
    std::vector<float> state;
    state.reserve(scene.animated_lights.size());
    for (const AnimatedLight& a : scene.animated_lights) state.push_back(a.animation.scale_at(time_s));
    return state;
}

std::size_t Scene::triangle_count() const {
    std::size_t total = 0;
    for (const Instance& instance : instances) total += meshes.at(instance.mesh).triangle_count();
    return total;
}

}  // namespace mogao
