// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/trace/render_scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "renderfarm/trace/texture_lod.h"

namespace mogao {
namespace {

[[noreturn]] void invalid(const Scene& scene, const std::string& what) {
    throw std::invalid_argument("scene '" + scene.source + "': " + what);
}

void validate_mesh_indices(const Scene& scene, std::size_t index, const Mesh& mesh) {
    const auto vertex_count = mesh.positions.size();
    if ((!mesh.colors.empty() && mesh.colors.size() != vertex_count) ||
        (!mesh.uvs.empty() && mesh.uvs.size() != vertex_count)) {
        invalid(scene, "mesh " + std::to_string(index) + " has colours or uvs not matching its " +
                           std::to_string(vertex_count) + " positions");
    }
    if (!mesh.normals.empty() && mesh.normals.size() != vertex_count) {
        invalid(scene, "mesh " + std::to_string(index) + " has " + std::to_string(mesh.normals.size()) +
                           " normals for " + std::to_string(vertex_count) + " positions");
    }
    for (std::size_t i = 0; i < vertex_count; ++i) {  // meshes built in code skip validate_mesh
        if (!mesh.positions[i].allFinite()) {
            invalid(scene, "mesh " + std::to_string(index) + " vertex " + std::to_string(i) + " is not finite");
        }
    }
    for (const auto& tri : mesh.triangles) {
        if (tri[0] >= vertex_count || tri[1] >= vertex_count || tri[2] >= vertex_count) {
            invalid(scene, "mesh " + std::to_string(index) +
                               " has a triangle index >= " + std::to_string(vertex_count) + " vertices");
        }
    }
}

// Embree allocates and pads the vertex buffer itself (see header for why positions are copied).
float* new_vertex_buffer(const EmbreeDevice& device, RTCGeometry g, std::size_t count) {
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), count));
    device.check("rtcSetNewGeometryBuffer(vertex)");
    return vertices;
}

// A static triangle geometry over `mesh`'s indices (shared), its vertices filled by the caller.
EmbreeGeometry new_triangles(const EmbreeDevice& device, const Mesh& mesh, RTCBuildQuality quality) {
    EmbreeGeometry geometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    static_assert(sizeof(std::array<std::uint32_t, 3>) == 3 * sizeof(std::uint32_t));
    rtcSetSharedGeometryBuffer(geometry.get(), RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, mesh.triangles.data(), 0,
                               3 * sizeof(std::uint32_t), mesh.triangles.size());
    rtcSetGeometryBuildQuality(geometry.get(), quality);
    return geometry;
}

EmbreeScene new_blas(const EmbreeDevice& device, const Scene& scene, const BvhOptions& bvh) {
    EmbreeScene blas(device);
    rtcSetSceneBuildQuality(blas.get(), bvh.quality);
    RTCSceneFlags flags = RTC_SCENE_FLAG_NONE;
    if (scene.robust_intersection) flags = flags | RTC_SCENE_FLAG_ROBUST;  // Scene::robust_intersection
    if (bvh.compact) flags = flags | RTC_SCENE_FLAG_COMPACT;
    rtcSetSceneFlags(blas.get(), flags);
    return blas;
}

EmbreeScene build_blas(const EmbreeDevice& device, const Scene& scene, const Mesh& mesh, const BvhOptions& bvh) {
    EmbreeGeometry geometry = new_triangles(device, mesh, bvh.quality);
    float* vertices = new_vertex_buffer(device, geometry.get(), mesh.positions.size());
    static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float));
    if (!mesh.positions.empty()) {
        std::memcpy(vertices, mesh.positions.data(), mesh.positions.size() * sizeof(Eigen::Vector3f));
    }
    rtcCommitGeometry(geometry.get());
    device.check("rtcCommitGeometry(triangles)");
    EmbreeScene blas = new_blas(device, scene, bvh);
    rtcAttachGeometryByID(blas.get(), geometry.get(), 0);
    rtcCommitScene(blas.get());
    device.check("rtcCommitScene(mesh '" + mesh.source + "')");
    return blas;  // the scene holds its own reference to the geometry
}

// Which instances go into the shared BLAS: those of meshes placed once, and of meshes whose copies
// together stay small (so a scan placed many times is never multiplied in memory).
std::vector<bool> choose_flattened(const Scene& scene, const BvhOptions& bvh) {
    std::vector<std::size_t> placements(scene.meshes.size(), 0);
    for (const Instance& inst : scene.instances) ++placements[inst.mesh];
    std::vector<bool> flat(scene.instances.size(), false);
    // A scene that asks for watertight intersection keeps every mesh in its own object space: the
    // world-space copy (rounded once to float) let 1-3 of 60,810 rays aimed at shared edges and
    // vertices through in RendererStability's closed mesh, the instanced mesh none.
    if (!bvh.flatten || scene.robust_intersection) return flat;
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
        const std::size_t m = scene.instances[i].mesh;
        flat[i] = placements[m] == 1 || scene.meshes[m].triangle_count() * placements[m] <= bvh.flatten_max_triangles;
    }
    return flat;
}

Eigen::Affine3d placement(const Instance& inst, const Mesh& mesh) {
    // Mesh positions are offsets from mesh.origin (mesh.h); 0 for recentred meshes.
    return inst.object_to_world * Eigen::Translation3d(mesh.origin);
}

}  // namespace

RenderScene::RenderScene(const Scene& scene, const std::string& embree_config, const BvhOptions& bvh)
    : device_(embree_config), tlas_(device_), flat_id_(static_cast<std::uint32_t>(scene.instances.size())) {
    std::vector<bool> used(scene.meshes.size(), false);
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& inst = scene.instances[i];
        const std::string name = "instance " + std::to_string(i) + " ('" + inst.name + "')";
        if (inst.mesh >= scene.meshes.size()) invalid(scene, name + " mesh index out of range");
        if (inst.material >= scene.materials.size()) invalid(scene, name + " material index out of range");
        const Eigen::Matrix3d linear = inst.object_to_world.linear();
        if (!inst.object_to_world.matrix().allFinite() || !(std::abs(linear.determinant()) > 0.0)) {
            invalid(scene, name + " transform is not finite and invertible");
        }
        used[inst.mesh] = true;
    }
    for (std::size_t m = 0; m < scene.meshes.size(); ++m)
        if (used[m]) validate_mesh_indices(scene, m, scene.meshes[m]);

    instances_.reserve(scene.instances.size());
    for (const Instance& inst : scene.instances) {
        const Mesh& mesh = scene.meshes[inst.mesh];
        InstanceData data;
        data.mesh = &mesh;
        data.material = static_cast<std::uint32_t>(inst.material);
        data.smooth = !mesh.normals.empty();
        data.tinted = !mesh.colors.empty() || (mesh.texture != nullptr && !mesh.uvs.empty());
        data.object_to_world = placement(inst, mesh);
        data.normal_matrix = inst.object_to_world.linear().inverse().transpose().cast<float>();
        data.ng_matrix = data.normal_matrix;
        data.linear = inst.object_to_world.linear().cast<float>();
        instances_.push_back(data);
    }
    const std::vector<bool> flat = choose_flattened(scene, bvh);
    // The TLAS is re-committed every frame with new float transforms.
    rtcSetSceneFlags(tlas_.get(), RTC_SCENE_FLAG_DYNAMIC);
    rtcSetSceneBuildQuality(tlas_.get(), RTC_BUILD_QUALITY_LOW);
    build_instanced(scene, flat, bvh);
    build_flattened(scene, flat, bvh);
    commit_transforms();
}

// One BLAS per mesh with an instanced placement (unused meshes cost nothing), one TLAS instance each.
void RenderScene::build_instanced(const Scene& scene, const std::vector<bool>& flat, const BvhOptions& bvh) {
    std::vector<bool> needed(scene.meshes.size(), false);
    for (std::size_t i = 0; i < scene.instances.size(); ++i)
        if (!flat[i]) needed[scene.instances[i].mesh] = true;
    blas_.reserve(scene.meshes.size());
    for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
        if (needed[m]) {
            blas_.push_back(build_blas(device_, scene, scene.meshes[m], bvh));
        } else {
            blas_.emplace_back(device_);  // never built
        }
    }
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
        if (flat[i]) continue;
        EmbreeGeometry geometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(geometry.get(), blas_[scene.instances[i].mesh].get());
        rtcSetGeometryTimeStepCount(geometry.get(), 1);
        rtcAttachGeometryByID(tlas_.get(), geometry.get(), static_cast<unsigned>(i));
        device_.check("rtcAttachGeometryByID(instance)");
        instance_geometry_.push_back(std::move(geometry));
        instanced_.push_back(static_cast<std::uint32_t>(i));
    }
}

// The shared BLAS: each flattened instance's vertices in world space relative to anchor_ (double
// arithmetic, one rounding to float), geometry id = instance index; Embree's Ng is then world-space.
void RenderScene::build_flattened(const Scene& scene, const std::vector<bool>& flat, const BvhOptions& bvh) {
    Eigen::AlignedBox3d box;
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
        if (!flat[i]) continue;
        for (const Eigen::Vector3f& p : instances_[i].mesh->positions)
            box.extend(instances_[i].object_to_world * p.cast<double>());
    }
    flattened_ = static_cast<std::size_t>(std::count(flat.begin(), flat.end(), true));
    if (flattened_ == 0) return;
    anchor_ = box.isEmpty() ? Eigen::Vector3d(Eigen::Vector3d::Zero()) : Eigen::Vector3d(box.center());
    EmbreeScene shared = new_blas(device_, scene, bvh);
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
        if (!flat[i]) continue;
        InstanceData& inst = instances_[i];
        const Mesh& mesh = *inst.mesh;
        EmbreeGeometry geometry = new_triangles(device_, mesh, bvh.quality);
        float* vertices = new_vertex_buffer(device_, geometry.get(), mesh.positions.size());
        for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
            const Eigen::Vector3f p = (inst.object_to_world * mesh.positions[v].cast<double>() - anchor_).cast<float>();
            std::memcpy(vertices + 3 * v, p.data(), 3 * sizeof(float));
        }
        rtcCommitGeometry(geometry.get());
        device_.check("rtcCommitGeometry(triangles)");
        rtcAttachGeometryByID(shared.get(), geometry.get(), static_cast<unsigned>(i));
        device_.check("rtcAttachGeometryByID(flattened instance)");
        inst.ng_matrix = Eigen::Matrix3f::Identity();
    }
    rtcCommitScene(shared.get());
    device_.check("rtcCommitScene(flattened instances)");
    EmbreeGeometry group(device_, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(group.get(), shared.get());
    rtcSetGeometryTimeStepCount(group.get(), 1);
    rtcAttachGeometryByID(tlas_.get(), group.get(), flat_id_);
    device_.check("rtcAttachGeometryByID(flattened group)");
    flat_blas_.push_back(std::move(shared));
    flat_instance_.push_back(std::move(group));
}

void RenderScene::rebase(const Eigen::Vector3d& origin) {
    if (origin == origin_) return;
    origin_ = origin;
    commit_transforms();
}

namespace {

// Embree's column-major 3x4 transform of `linear` and `translation` (computed in double, rounded once).
void set_transform(RTCGeometry g, const Eigen::Matrix3d& linear, const Eigen::Vector3d& translation) {
    std::array<float, 12> column_major{};
    for (int c = 0; c < 3; ++c) {
        for (int r = 0; r < 3; ++r)
            column_major[static_cast<std::size_t>(c * 3 + r)] = static_cast<float>(linear(r, c));
    }
    for (int r = 0; r < 3; ++r) column_major[static_cast<std::size_t>(9 + r)] = static_cast<float>(translation[r]);
    rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, column_major.data());
    rtcCommitGeometry(g);
}

}  // namespace

void RenderScene::commit_transforms() {
    // Subtract in double, then round once to float: the float transform only carries the (small)
    // offset from the eye, never the large absolute translation.
    for (std::size_t k = 0; k < instanced_.size(); ++k) {
        const Eigen::Affine3d& xf = instances_[instanced_[k]].object_to_world;
        set_transform(instance_geometry_[k].get(), xf.linear(), xf.translation() - origin_);
    }
    for (const EmbreeGeometry& group : flat_instance_)
        set_transform(group.get(), Eigen::Matrix3d::Identity(), anchor_ - origin_);
    rtcCommitScene(tlas_.get());
    device_.check("rtcCommitScene(instances)");
}

Eigen::Vector3f RenderScene::tint_at(const InstanceData& inst, std::uint32_t primitive, float u, float v,
                                     float cone_width, float cos_incidence) {
    const Mesh& mesh = *inst.mesh;
    const auto& tri = mesh.triangles[primitive];
    const float w = 1.0f - u - v;
    Eigen::Vector3f tint = Eigen::Vector3f::Ones();
    if (!mesh.colors.empty()) tint = w * mesh.colors[tri[0]] + u * mesh.colors[tri[1]] + v * mesh.colors[tri[2]];
    if (mesh.texture && !mesh.uvs.empty()) {
        const Eigen::Vector2f& t0 = mesh.uvs[tri[0]];
        const Eigen::Vector2f uv = w * t0 + u * mesh.uvs[tri[1]] + v * mesh.uvs[tri[2]];
        float lod = 0.0f;
        if (cone_width > 0.0f) {
            const Eigen::Vector2f d1 = mesh.uvs[tri[1]] - t0, d2 = mesh.uvs[tri[2]] - t0;
            const ImageSize size = mesh.texture->image.size;
            const float texel_area = static_cast<float>(size.width) * static_cast<float>(size.height) *
                                     std::abs(d1.x() * d2.y() - d1.y() * d2.x());
            const Eigen::Vector3f& p0 = mesh.positions[tri[0]];
            const float world_area =
                (inst.linear * (mesh.positions[tri[1]] - p0)).cross(inst.linear * (mesh.positions[tri[2]] - p0)).norm();
            lod = texture_lod(cone_width, cos_incidence, texel_area, world_area);
        }
        tint = tint.cwiseProduct(mesh.texture->sample(uv, lod));
    }
    return tint;
}

SurfaceHit RenderScene::surface(const Eigen::Vector3f& org, const Eigen::Vector3f& dir, float t,
                                std::uint32_t instance_id, std::uint32_t geometry_id, std::uint32_t primitive, float u,
                                float v, const Eigen::Vector3f& ng_blas, float cone_width) const {
    const InstanceData& inst = instances_[instance_id == flat_id_ ? geometry_id : instance_id];
    SurfaceHit hit;
    hit.position = org + t * dir;
    hit.material = inst.material;
    Eigen::Vector3f ng = (inst.ng_matrix * ng_blas).normalized();
    if (ng.dot(dir) > 0.0f) ng = -ng;  // face the incoming ray: meshes are two-sided
    hit.geometric_normal = ng;
    hit.cone_width = cone_width;
    if (inst.tinted) {
        hit.tinted = true;
        hit.tint = tint_at(inst, primitive, u, v, cone_width, std::abs(ng.dot(dir)));
    }
    if (!inst.smooth) {
        hit.shading_normal = ng;
        return hit;
    }
    const auto& tri = inst.mesh->triangles[primitive];
    const auto& normals = inst.mesh->normals;
    const Eigen::Vector3f n_object = (1.0f - u - v) * normals[tri[0]] + u * normals[tri[1]] + v * normals[tri[2]];
    Eigen::Vector3f n = inst.normal_matrix * n_object;
    const float length = n.norm();
    n = length > 0.0f ? Eigen::Vector3f(n / length) : ng;
    hit.shading_normal = n.dot(ng) < 0.0f ? Eigen::Vector3f(-n) : n;
    return hit;
}

}  // namespace mogao
