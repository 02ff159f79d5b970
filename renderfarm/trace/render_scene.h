// SPDX-License-Identifier: Apache-2.0
// Embree geometry of a Scene: one bottom-level BVH (BLAS) per referenced Mesh and a top-level
// scene (TLAS) holding every Instance as an Embree instance, so a mesh placed N times is built
// and stored once (the 6-million-triangle scans are instanced, never copied).
//
// Precision far from the origin: object_to_world transforms stay double. rebase(origin) moves
// the world so that `origin` (the camera eye, in practice) maps to 0: each instance's float
// transform is (object_to_world with translation - origin computed in double), the TLAS is
// re-committed (cheap: it only holds instances). Rays then start near 0 and hit points are
// float values of small magnitude, whatever the scene's absolute coordinates.
//
// Memory / lifetime: vertex positions are copied into Embree buffers (Embree requires 16-byte
// readable padding after the last vertex, which std::vector does not promise); triangle indices
// and vertex normals are shared with the Scene, so the Scene must outlive the RenderScene.
// Thread safety: surface(), root() are const and safe to call concurrently; rebase() is not.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <embree3/rtcore.h>

#include "renderfarm/scene/scene.h"
#include "renderfarm/trace/embree_device.h"
#include "renderfarm/trace/embree_scene.h"

namespace mogao {

// A ray hit resolved for shading, in the rebased float frame.
struct SurfaceHit {
    Eigen::Vector3f position;                        // rebased world metres (org + t dir)
    Eigen::Vector3f geometric_normal;                // unit, facing the incoming ray
    Eigen::Vector3f shading_normal;                  // unit; interpolated vertex normal or = geometric_normal,
                                                     // flipped to the geometric normal's side
    std::uint32_t material = 0;                      // index into Scene::materials
    bool tinted = false;                             // the mesh has vertex colours or a texture
    Eigen::Vector3f tint = Eigen::Vector3f::Ones();  // linear RGB multiplying the albedo: the
                                                     // interpolated vertex colour times the texture
                                                     // filtered at the interpolated uv for the ray
                                                     // cone's footprint (texture.h, texture_lod.h)
    float cone_width = 0.0f;  // metres: the width of the ray cone at this hit (texture_lod.h); 0:
                              // no footprint (level 0, bilinear)
};

class RenderScene {
public:
    // Builds the BLAS of every mesh used by an instance (RTC_BUILD_QUALITY_HIGH, static) and the
    // TLAS. Throws std::invalid_argument for an instance whose mesh/material index is out of
    // range, a non-finite or singular transform, a triangle index >= positions.size(), or
    // normals.size() not in {0, positions.size()}; std::runtime_error for Embree errors.
    RenderScene(const Scene& scene, const std::string& embree_config);

    // Moves the world origin to `origin` (world metres) and re-commits the TLAS; a no-op when
    // the origin did not change.
    void rebase(const Eigen::Vector3d& origin);
    [[nodiscard]] const Eigen::Vector3d& origin() const { return origin_; }

    [[nodiscard]] RTCScene root() const { return tlas_.get(); }

    // Resolves an Embree hit: instance id, primitive id, barycentrics (u weights vertex 1, v
    // vertex 2) and the object-space geometric normal Ng as Embree reports it for instances.
    // cone_width (metres, >= 0) is the ray cone's width at the hit; a texture is filtered over it
    // (texture_lod.h), 0 samples level 0.
    [[nodiscard]] SurfaceHit surface(const Eigen::Vector3f& org, const Eigen::Vector3f& dir, float t,
                                     std::uint32_t instance, std::uint32_t primitive, float u, float v,
                                     const Eigen::Vector3f& ng_object, float cone_width = 0.0f) const;

private:
    struct InstanceData {
        const Mesh* mesh = nullptr;
        std::uint32_t material = 0;
        bool smooth = false;              // mesh has vertex normals
        bool tinted = false;              // mesh has vertex colours or a texture
        Eigen::Affine3d object_to_world;  // double, world metres
        Eigen::Matrix3f normal_matrix;    // inverse transpose of the linear part
        Eigen::Matrix3f linear;           // the linear part (world triangle areas for texture_lod.h)
    };

    void commit_transforms();
    [[nodiscard]] static Eigen::Vector3f tint_at(const InstanceData& inst, std::uint32_t primitive, float u, float v,
                                                 float cone_width, float cos_incidence);

    EmbreeDevice device_;
    std::vector<EmbreeScene> blas_;  // per mesh; empty owner for unused meshes
    EmbreeScene tlas_;
    std::vector<EmbreeGeometry> instance_geometry_;  // per instance (id = instance index)
    std::vector<InstanceData> instances_;
    Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
};

}  // namespace mogao
