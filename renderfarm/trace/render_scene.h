// SPDX-License-Identifier: Apache-2.0
// Embree geometry of a Scene: a top-level scene (TLAS) of Embree instances over bottom-level BVHs
// (BLAS). By default (BvhOptions::flatten) the instances are flattened: every instance of a mesh
// placed once, or of a mesh whose copies stay small, is copied in world space into ONE shared BLAS (one geometry per
// instance, geometry id = instance index), which the TLAS holds as a single instance. Any other mesh
// placed several times keeps its own BLAS, built and stored once, and one TLAS instance per
// placement. Why: in a two-level BVH whose instance boxes overlap (a room whose box encloses every
// exhibit) each ray descends several BVHs; one BVH over all the static triangles separates them
// (mogao_bench_bvh measures it; docs/renderer.md, "BVH choices").
//
// Precision far from the origin: object_to_world transforms stay double. The flattened copy holds
// each vertex relative to an anchor (the centre of the flattened vertices' box, computed in
// double), so its floats carry only offsets within the scene. rebase(origin) moves the world so
// that `origin` (the camera eye, in practice) maps to 0: each TLAS instance's float transform is
// computed in double with `origin` subtracted (the shared BLAS's is the translation anchor -
// origin), and the TLAS is re-committed (cheap: it only holds instances). Rays then start near 0
// and hit points are float values of small magnitude, whatever the scene's absolute coordinates.
//
// Memory / lifetime: vertex positions are copied into Embree buffers (Embree requires 16-byte
// readable padding after the last vertex, which std::vector does not promise); a flattened
// instance's positions are its own world-space copy. Triangle indices and vertex normals are
// shared with the Scene, so the Scene must outlive the RenderScene.
// Thread safety: surface(), root() are const and safe to call concurrently; rebase() is not.
#pragma once

#include <cstddef>
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

// How the BVHs are built. Every choice renders the same image up to float rounding of the hit points;
// they differ in build time, memory and traversal speed (mogao_bench_bvh, docs/renderer.md).
struct BvhOptions {
    // One shared BLAS for the instances of meshes placed once and of meshes whose copies total at
    // most flatten_max_triangles triangles (see the file comment); false: one BLAS per mesh and one TLAS
    // instance per placement, every mesh stored once. A scene with robust_intersection is never
    // flattened (its meshes stay watertight in their own object space).
    bool flatten = true;
    // A mesh placed more than once is copied per placement only while its copies total at most this
    // many triangles (its triangles times its placements).
    std::size_t flatten_max_triangles = 65536;
    // Embree's build quality of the static BLASes (RTC_BUILD_QUALITY_LOW/MEDIUM/HIGH).
    RTCBuildQuality quality = RTC_BUILD_QUALITY_HIGH;
    // RTC_SCENE_FLAG_COMPACT on the BLASes: a smaller BVH, usually slower to traverse.
    bool compact = false;
};

class RenderScene {
public:
    // Builds the BLASes of the meshes used by an instance (static, bvh.quality) and the TLAS.
    // Throws std::invalid_argument for an instance whose mesh/material index is out of range, a
    // non-finite or singular transform, a triangle index >= positions.size(), or normals.size()
    // not in {0, positions.size()}; std::runtime_error for Embree errors.
    RenderScene(const Scene& scene, const std::string& embree_config, const BvhOptions& bvh = {});

    // Moves the world origin to `origin` (world metres) and re-commits the TLAS; a no-op when
    // the origin did not change.
    void rebase(const Eigen::Vector3d& origin);
    [[nodiscard]] const Eigen::Vector3d& origin() const { return origin_; }

    [[nodiscard]] RTCScene root() const { return tlas_.get(); }

    // Bytes Embree holds for this scene's BVHs and vertex buffers (EmbreeDevice::allocated_bytes).
    [[nodiscard]] std::int64_t bvh_bytes() const noexcept { return device_.allocated_bytes(); }

    // Instances flattened into the shared BLAS (BvhOptions::flatten), of scene.instances.size().
    [[nodiscard]] std::size_t flattened_instances() const { return flattened_; }

    // Resolves an Embree hit: its instance and geometry ids (instID[0], geomID), primitive id,
    // barycentrics (u weights vertex 1, v vertex 2) and the geometric normal Ng as Embree reports
    // it (in the space of the BLAS that was hit). cone_width (metres, >= 0) is the ray cone's width
    // at the hit; a texture is filtered over it (texture_lod.h), 0 samples level 0.
    [[nodiscard]] SurfaceHit surface(const Eigen::Vector3f& org, const Eigen::Vector3f& dir, float t,
                                     std::uint32_t instance_id, std::uint32_t geometry_id, std::uint32_t primitive,
                                     float u, float v, const Eigen::Vector3f& ng_blas, float cone_width = 0.0f) const;

private:
    struct InstanceData {
        const Mesh* mesh = nullptr;
        std::uint32_t material = 0;
        bool smooth = false;              // mesh has vertex normals
        bool tinted = false;              // mesh has vertex colours or a texture
        Eigen::Affine3d object_to_world;  // double, world metres
        Eigen::Matrix3f normal_matrix;    // inverse transpose of the linear part
        Eigen::Matrix3f ng_matrix;        // Embree's Ng to world: normal_matrix, or identity when flattened
        Eigen::Matrix3f linear;           // the linear part (world triangle areas for texture_lod.h)
    };

    void build_instanced(const Scene& scene, const std::vector<bool>& flat, const BvhOptions& bvh);
    void build_flattened(const Scene& scene, const std::vector<bool>& flat, const BvhOptions& bvh);
    void commit_transforms();
    [[nodiscard]] static Eigen::Vector3f tint_at(const InstanceData& inst, std::uint32_t primitive, float u, float v,
                                                 float cone_width, float cos_incidence);

    EmbreeDevice device_;
    std::vector<EmbreeScene> blas_;  // per mesh; empty owner for meshes with no instanced placement
    EmbreeScene tlas_;
    std::vector<EmbreeGeometry> instance_geometry_;  // per instanced placement (TLAS id = instance index)
    std::vector<std::uint32_t> instanced_;           // their instance indices, in the same order
    std::vector<EmbreeScene> flat_blas_;             // the shared BLAS, or empty when nothing is flattened
    std::vector<EmbreeGeometry> flat_instance_;      // its TLAS instance (id = flat_id_), or empty
    std::uint32_t flat_id_ = 0;                      // = instances_.size(), beyond every instance index
    std::size_t flattened_ = 0;
    Eigen::Vector3d anchor_ = Eigen::Vector3d::Zero();  // world metres; the shared BLAS's vertices are relative to it
    std::vector<InstanceData> instances_;
    Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
};

}  // namespace mogao
