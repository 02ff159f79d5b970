// SPDX-License-Identifier: Apache-2.0
// The lights of a Scene prepared for shading: directions normalised, positions rebased onto the
// frame origin (see render_scene.h), lights with zero power dropped, environment lights summed.
// "Model only what the scene asks for": empty lists make the corresponding loops free, and
// `any_shadows` tells whether any shadow ray can ever be traced.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "renderfarm/scene/scene.h"

namespace mogao {

struct PreparedDirectional {
    Eigen::Vector3f to_light;    // unit, world (translation-free, so not rebased)
    Eigen::Vector3f irradiance;  // W/m² per channel on a surface facing the light
    bool cast_shadows = true;
};

struct PreparedPoint {
    Eigen::Vector3d world_position;  // metres
    Eigen::Vector3f position;        // rebased, float
    Eigen::Vector3f intensity;       // W/sr
    bool cast_shadows = true;
};

struct PreparedArea {
    Eigen::Vector3d world_corner;    // metres
    Eigen::Vector3f corner;          // rebased, float
    Eigen::Vector3f edge_u, edge_v;  // metres
    Eigen::Vector3f normal;          // unit, edge_u x edge_v: the emitting side
    float area = 0.0f;               // m²
    Eigen::Vector3f radiance;        // W/(sr·m²)
    bool cast_shadows = true;
};

struct LightSet {
    std::vector<PreparedDirectional> directional;
    std::vector<PreparedPoint> point;
    std::vector<PreparedArea> area;
    Eigen::Vector3f environment = Eigen::Vector3f::Zero();  // summed constant radiance
    bool has_environment = false;
    bool any_shadows = false;

    // The lights at scene time `time_s`: each one's power times its animation's factor then
    // (LightAnimation::scale_at; a factor of 0 drops the light). Throws std::invalid_argument for
    // non-finite values, a zero directional direction or a degenerate area light (|edge_u x edge_v| == 0).
    [[nodiscard]] static LightSet from_scene(const Scene& scene, double time_s = 0.0);
    void rebase(const Eigen::Vector3d& origin);
};

}  // namespace mogao
