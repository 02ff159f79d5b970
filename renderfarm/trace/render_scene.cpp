// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/trace/render_scene.h"

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

EmbreeScene build_blas(const EmbreeDevice& device, const Mesh& mesh, bool robust) {
    EmbreeGeometry geometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    const RTCGeometry g = geometry.get();
    // Embree allocates and pads the vertex buffer itself (see header for why this is a copy).
    auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                 3 * sizeof(float), mesh.positions.size()));
    device.check("rtcSetNewGeometryBuffer(vertex)");
    static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float));
    if (!mesh.positions.empty()) {
        std::memcpy(vertices, mesh.positions.data(), mesh.positions.size() * sizeof(Eigen::Vector3f));
    }
    static_assert(sizeof(std::array<std::uint32_t, 3>) == 3 * sizeof(std::uint32_t));
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, mesh.triangles.data(), 0,
                               3 * sizeof(std::uint32_t), mesh.triangles.size());
    rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
    rtcCommitGeometry(g);
    device.check("rtcCommitGeometry(triangles)");

    EmbreeScene blas(device);
    rtcSetSceneBuildQuality(blas.get(), RTC_BUILD_QUALITY_HIGH);
    if (robust) rtcSetSceneFlags(blas.get(), RTC_SCENE_FLAG_ROBUST);  // Scene::robust_intersection
    rtcAttachGeometryByID(blas.get(), g, 0);
    rtcCommitScene(blas.get());
    device.check("rtcCommitScene(mesh '" + mesh.source + "')");
    return blas;  // the scene holds its own reference to the geometry
}

}  // namespace

RenderScene::RenderScene(const Scene& scene, const std::string& embree_config)
    : device_(embree_config), tlas_(device_) {
    blas_.reserve(scene.meshes.size());
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
    for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
        if (used[m]) {
            validate_mesh_indices(scene, m, scene.meshes[m]);
            blas_.push_back(build_blas(device_, scene.meshes[m], scene.robust_intersection));
        } else {
            blas_.emplace_back(device_);  // never built: unused meshes cost nothing
        }
    }

    // The TLAS is re-committed every frame with new float transforms.
    rtcSetSceneFlags(tlas_.get(), RTC_SCENE_FLAG_DYNAMIC);
    rtcSetSceneBuildQuality(tlas_.get(), RTC_BUILD_QUALITY_LOW);
    instances_.reserve(scene.instances.size());
    instance_geometry_.reserve(scene.instances.size());
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& inst = scene.instances[i];
        const Mesh& mesh = scene.meshes[inst.mesh];
        InstanceData data;
        data.mesh = &mesh;
        data.material = static_cast<std::uint32_t>(inst.material);
        data.smooth = !mesh.normals.empty();
        data.tinted = !mesh.colors.empty() || (mesh.texture != nullptr && !mesh.uvs.empty());
        // Mesh positions are offsets from mesh.origin (mesh.h); 0 for recentred meshes.
        data.object_to_world = inst.object_to_world * Eigen::Translation3d(mesh.origin);
        data.normal_matrix = inst.object_to_world.linear().inverse().transpose().cast<float>();
        data.linear = inst.object_to_world.linear().cast<float>();
        instances_.push_back(data);

        EmbreeGeometry geometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(geometry.get(), blas_[inst.mesh].get());
        rtcSetGeometryTimeStepCount(geometry.get(), 1);
        rtcAttachGeometryByID(tlas_.get(), geometry.get(), static_cast<unsigned>(i));
        device_.check("rtcAttachGeometryByID(instance)");
        instance_geometry_.push_back(std::move(geometry));
    }
    commit_transforms();
}

void RenderScene::rebase(const Eigen::Vector3d& origin) {
    if (origin == origin_) return;
    origin_ = origin;
    commit_transforms();
}

void RenderScene::commit_transforms() {
    for (std::size_t i = 0; i < instances_.size(); ++i) {
        const Eigen::Affine3d& xf = instances_[i].object_to_world;
        // Subtract in double, then round once to float: the float transform only carries the
        // (small) offset from the eye, never the large absolute translation.
        const Eigen::Vector3d translation = xf.translation() - origin_;
        std::array<float, 12> column_major{};
        for (int c = 0; c < 3; ++c) {
            for (int r = 0; r < 3; ++r)
                column_major[static_cast<std::size_t>(c * 3 + r)] = static_cast<float>(xf.linear()(r, c));
        }
        for (int r = 0; r < 3; ++r) column_major[static_cast<std::size_t>(9 + r)] = static_cast<float>(translation[r]);
        const RTCGeometry g = instance_geometry_[i].get();
        rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, column_major.data());
        rtcCommitGeometry(g);
    }
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

SurfaceHit RenderScene::surface(const Eigen::Vector3f& org, const Eigen::Vector3f& dir, float t, std::uint32_t instance,
                                std::uint32_t primitive, float u, float v, const Eigen::Vector3f& ng_object,
                                float cone_width) const {
    const InstanceData& inst = instances_[instance];
    SurfaceHit hit;
    hit.position = org + t * dir;
    hit.material = inst.material;
    Eigen::Vector3f ng = (inst.normal_matrix * ng_object).normalized();
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
