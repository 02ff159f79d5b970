// SPDX-License-Identifier: Apache-2.0
// The scene a farm renders: meshes placed by per-object transforms, materials, lights and the
// viewer. Produced by load_scene() from a scene file (schema: docs/scene-format.md).
//
// World frame: right-handed, metres, +y up (same as view/view_request.h).
// Meshes keep their file units; each instance's object_to_world carries scale (e.g. 0.001 for
// millimetre scans), rotation and translation. Meshes are re-centred on load (recentre_mesh) so
// that their local coordinates stay near the origin in float; the offset is folded into the
// transforms, in double precision.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/viewer.h"
#include "renderfarm/scene/mesh.h"

namespace mogao {

using Rgb = Eigen::Vector3f;  // linear RGB

// A light's power over time (scene file "animation"): piecewise constant, `scale[i]` multiplies the
// light's irradiance, intensity or radiance from i * step_s to (i + 1) * step_s seconds of scene
// time, the list repeating (a lighting cue, a flickering lamp). Scene time is the farm's: seconds
// since it began serving (0 for path tours). An empty list is the light as given, at every time.
struct LightAnimation {
    double step_s = 1.0;       // > 0
    std::vector<float> scale;  // each >= 0

    // The factor at `time_s` (times before 0 and non-finite ones count as 0); 1 for an empty list.
    [[nodiscard]] float scale_at(double time_s) const;
};

struct Material {
    std::string name;
    Rgb albedo{0.7f, 0.7f, 0.7f};  // diffuse reflectance, each channel in [0, 1]
    Rgb specular{0.f, 0.f, 0.f};   // Blinn-Phong specular reflectance; zero = no glossy term
    float shininess = 32.f;        // Blinn-Phong exponent
};

struct Instance {
    std::string name;
    std::size_t mesh = 0;      // index into Scene::meshes
    std::size_t material = 0;  // index into Scene::materials
    Eigen::Affine3d object_to_world = Eigen::Affine3d::Identity();
};

// Sun: parallel light arriving from `direction_to_light` with irradiance (W/m² per channel) on a
// surface facing it.
struct DirectionalLight {
    Eigen::Vector3d direction_to_light{0.0, 1.0, 0.0};  // unit vector, world
    Rgb irradiance{3.f, 3.f, 3.f};
    bool cast_shadows = true;
};

// Isotropic point light; irradiance at distance d is intensity / d².
struct PointLight {
    Eigen::Vector3d position{0.0, 2.0, 0.0};  // world metres
    Rgb intensity{10.f, 10.f, 10.f};          // W/sr per channel
    bool cast_shadows = true;
};

// One-sided emitting parallelogram corner + s*edge_u + t*edge_v, s,t in [0,1]; it emits toward
// edge_u x edge_v. Not visible to camera rays (it lights the scene only).
struct AreaLight {
    Eigen::Vector3d corner{0.0, 3.0, 0.0};
    Eigen::Vector3d edge_u{1.0, 0.0, 0.0};
    Eigen::Vector3d edge_v{0.0, 0.0, 1.0};
    Rgb radiance{5.f, 5.f, 5.f};  // W/(sr·m²) per channel
    bool cast_shadows = true;
};

// Constant environment (sky) radiance arriving from every direction not blocked by the scene.
struct EnvironmentLight {
    Rgb radiance{0.2f, 0.2f, 0.25f};
};

enum class LightKind { sun, point, area };

// An animated light: which (its kind, its index in that kind's list of the Scene) and how.
struct AnimatedLight {
    LightKind kind = LightKind::point;
    std::size_t index = 0;
    LightAnimation animation;
};

// Display transform applied to exposure · L before the sRGB encoding (film.h has the formulas):
// clamp to [0, 1], Reinhard (x / (1 + x)) or the ACES filmic fit of Narkowicz 2015.
enum class ToneMap { clamp, reinhard, aces };

struct Scene {
    std::string source;  // scene file path, for messages
    std::vector<Mesh> meshes;
    std::vector<Material> materials;  // at least one
    std::vector<Instance> instances;
    std::vector<DirectionalLight> directional_lights;
    std::vector<PointLight> point_lights;
    std::vector<AreaLight> area_lights;
    std::vector<EnvironmentLight> environment_lights;
    std::vector<AnimatedLight> animated_lights;  // in the scene file's order; at most one per light
    Viewer viewer;
    float exposure = 1.f;               // multiplies radiance before the sRGB transfer
    ToneMap tone_map = ToneMap::clamp;  // scene file "tone_map": "clamp" | "reinhard" | "aces"
    // Scene file "robust_intersection": build every mesh BVH with Embree's RTC_SCENE_FLAG_ROBUST,
    // whose triangle test is watertight along shared edges and vertices. Off by default (14-22 %
    // slower): without it about 4 % of rays aimed exactly at the edges/vertices of a closed
    // icosphere pass through (renderer_stability_test.cpp); turn it on for closed rooms viewed
    // from inside where a speck of sky through an edge would show.
    bool robust_intersection = false;

    [[nodiscard]] std::size_t triangle_count() const;  // summed over instances
};

// The factor of light `index` of `kind` at `time_s`: its animation's, or 1 when it has none.
[[nodiscard]] float light_scale(const Scene& scene, LightKind kind, std::size_t index, double time_s);

// The lights' state at a scene time: every animated light's factor (LightAnimation::scale_at), in
// Scene::animated_lights' order. Equal states light the scene identically, so what was
// learnt under one (a radiance cache, a temporal history, a still view's accumulated samples) is
// valid under the other; a different state invalidates it. Empty when no light is animated.
[[nodiscard]] std::vector<float> lighting_state(const Scene& scene, double time_s);

}  // namespace mogao
