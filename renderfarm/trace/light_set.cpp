// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/trace/light_set.h"

#include <stdexcept>
#include <string>

namespace mogao {
namespace {

bool has_power(const Rgb& c) { return c.maxCoeff() > 0.0f; }

void require(bool ok, const Scene& scene, const std::string& what) {
    if (!ok) throw std::invalid_argument("scene '" + scene.source + "': " + what);
}

}  // namespace

LightSet LightSet::from_scene(const Scene& scene, double time_s) {
    LightSet set;
    for (std::size_t i = 0; i < scene.directional_lights.size(); ++i) {
        const DirectionalLight& l = scene.directional_lights[i];
        const double length = l.direction_to_light.norm();
        require(l.direction_to_light.allFinite() && length > 0.0 && l.irradiance.allFinite(), scene,
                "directional light " + std::to_string(i) + " needs a finite non-zero direction and finite irradiance");
        const Rgb irradiance = l.irradiance * light_scale(scene, LightKind::sun, i, time_s);
        if (!has_power(irradiance)) continue;
        set.directional.push_back({(l.direction_to_light / length).cast<float>(), irradiance, l.cast_shadows});
    }
    for (std::size_t i = 0; i < scene.point_lights.size(); ++i) {
        const PointLight& l = scene.point_lights[i];
        require(l.position.allFinite() && l.intensity.allFinite(), scene,
                "point light " + std::to_string(i) + " needs finite position and intensity");
        const Rgb intensity = l.intensity * light_scale(scene, LightKind::point, i, time_s);
        if (!has_power(intensity)) continue;
        set.point.push_back({l.position, l.position.cast<float>(), intensity, l.cast_shadows});
    }
    for (std::size_t i = 0; i < scene.area_lights.size(); ++i) {
        const AreaLight& l = scene.area_lights[i];
        const Eigen::Vector3d cross = l.edge_u.cross(l.edge_v);
        require(l.corner.allFinite() && l.edge_u.allFinite() && l.edge_v.allFinite() && l.radiance.allFinite() &&
                    cross.norm() > 0.0,
                scene, "area light " + std::to_string(i) + " needs finite values and non-parallel edges");
        const Rgb radiance = l.radiance * light_scale(scene, LightKind::area, i, time_s);
        if (!has_power(radiance)) continue;
        set.area.push_back({l.corner, l.corner.cast<float>(), l.edge_u.cast<float>(), l.edge_v.cast<float>(),
                            cross.normalized().cast<float>(), static_cast<float>(cross.norm()), radiance,
                            l.cast_shadows});
    }
    for (const EnvironmentLight& l : scene.environment_lights) {
        require(l.radiance.allFinite(), scene, "environment light needs finite radiance");
        set.environment += l.radiance;
    }
    set.has_environment = has_power(set.environment);
    for (const auto& l : set.directional) set.any_shadows |= l.cast_shadows;
    for (const auto& l : set.point) set.any_shadows |= l.cast_shadows;
    for (const auto& l : set.area) set.any_shadows |= l.cast_shadows;
    return set;
}

void LightSet::rebase(const Eigen::Vector3d& origin) {
    for (auto& l : point) l.position = (l.world_position - origin).cast<float>();
    for (auto& l : area) l.corner = (l.world_corner - origin).cast<float>();
}

}  // namespace mogao
