// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/trace/test_scenes.h"

#include "renderfarm/scene/procedural.h"

#include <cmath>
#include <numbers>

namespace mogao::test {

Mesh make_grid(int n, float half, bool with_normals) {
    Mesh mesh;
    mesh.source = "grid";
    for (int j = 0; j <= n; ++j) {
        for (int i = 0; i <= n; ++i) {
            const float x = -half + 2.0f * half * static_cast<float>(i) / static_cast<float>(n);
            const float z = -half + 2.0f * half * static_cast<float>(j) / static_cast<float>(n);
            mesh.positions.emplace_back(x, 0.0f, z);
            if (with_normals) mesh.normals.emplace_back(0.0f, 1.0f, 0.0f);
        }
    }
    const auto index = [n](int i, int j) { return static_cast<std::uint32_t>(j * (n + 1) + i); };
    for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
            mesh.triangles.push_back({index(i, j), index(i, j + 1), index(i + 1, j)});
            mesh.triangles.push_back({index(i + 1, j), index(i, j + 1), index(i + 1, j + 1)});
        }
    }
    return mesh;
}

Scene make_sphere_over_floor(const Eigen::Vector3d& offset) {
    Scene scene;
    scene.source = "sphere_over_floor";
    scene.meshes.push_back(make_uv_sphere(0.5, 64, 32));
    scene.meshes.push_back(make_grid(8, 2.0f, false));
    Material grey;
    grey.name = "grey";
    grey.albedo = Rgb(0.5f, 0.5f, 0.5f);
    Material glossy;
    glossy.name = "glossy";
    glossy.albedo = Rgb(0.6f, 0.3f, 0.2f);
    glossy.specular = Rgb(0.3f, 0.3f, 0.3f);
    glossy.shininess = 40.0f;
    scene.materials = {grey, glossy};
    Instance sphere{"sphere", 0, 1, Eigen::Affine3d::Identity()};
    sphere.object_to_world.translate(offset + Eigen::Vector3d(0.0, 1.0, 0.0));
    Instance floor{"floor", 1, 0, Eigen::Affine3d::Identity()};
    floor.object_to_world.translate(offset);
    scene.instances = {sphere, floor};
    return scene;
}

ViewRequest look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, ImageSize size, double fov_deg) {
    ViewRequest request;
    request.size = size;
    request.camera = PinholeCamera{fov_deg};
    request.pose.eye = eye;
    const Eigen::Vector3d d = (target - eye).normalized();
    // forward = Ry(yaw) Rx(pitch) (0,0,-1) = (-sin(yaw) cos(pitch), sin(pitch), -cos(yaw) cos(pitch))
    request.pose.pitch_deg = std::asin(d.y()) * 180.0 / std::numbers::pi;
    request.pose.yaw_deg = std::atan2(-d.x(), -d.z()) * 180.0 / std::numbers::pi;
    return request;
}

}  // namespace mogao::test
