// SPDX-License-Identifier: Apache-2.0
// Mesh checks and fix-ups declared in mesh_io.h: validate_mesh, compute_vertex_normals,
// recentre_mesh. Accumulation is in double so that large scans and far-off origins stay exact.
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include <Eigen/Geometry>
#include <fmt/format.h>

#include "renderfarm/scene/mesh_io.h"

namespace mogao {

void validate_mesh(const Mesh& mesh) {
    const std::string& file = mesh.source.empty() ? std::string("<unnamed mesh>") : mesh.source;
    const std::size_t n = mesh.positions.size();
    if (n > std::numeric_limits<std::uint32_t>::max()) {
        throw MeshLoadError(file, fmt::format("{} vertices exceed the 32-bit index limit", n));
    }
    if (mesh.triangles.empty()) throw MeshLoadError(file, fmt::format("empty mesh: no triangles ({} vertices)", n));
    for (std::size_t i = 0; i < n; ++i) {
        const Eigen::Vector3f& p = mesh.positions[i];
        if (!p.allFinite())
            throw MeshLoadError(
                file, fmt::format("vertex {}: coordinate is not finite ({}, {}, {})", i, p.x(), p.y(), p.z()));
    }
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        for (const std::uint32_t v : mesh.triangles[t]) {
            if (v >= n)
                throw MeshLoadError(file,
                                    fmt::format("triangle {}: vertex index {} out of range ({} vertices)", t, v, n));
        }
    }
    if (!mesh.normals.empty() && mesh.normals.size() != n) {
        throw MeshLoadError(file,
                            fmt::format("normals count mismatch: {} normals for {} vertices", mesh.normals.size(), n));
    }
    for (std::size_t i = 0; i < mesh.normals.size(); ++i) {
        if (!mesh.normals[i].allFinite()) throw MeshLoadError(file, fmt::format("normal {}: not finite", i));
    }
    if (!mesh.origin.allFinite()) throw MeshLoadError(file, "origin (bounding-box centre) is not finite");
    if (!mesh.colors.empty() && mesh.colors.size() != n) {
        throw MeshLoadError(file,
                            fmt::format("colours count mismatch: {} colours for {} vertices", mesh.colors.size(), n));
    }
    for (std::size_t i = 0; i < mesh.colors.size(); ++i) {
        const Eigen::Vector3f& c = mesh.colors[i];
        if (!(c.minCoeff() >= 0.0f && c.maxCoeff() <= 1.0f))
            throw MeshLoadError(file, fmt::format("colour {}: outside [0, 1]", i));
    }
    if (!mesh.uvs.empty() && mesh.uvs.size() != n) {
        throw MeshLoadError(file,
                            fmt::format("texture coordinates count mismatch: {} for {} vertices", mesh.uvs.size(), n));
    }
    for (std::size_t i = 0; i < mesh.uvs.size(); ++i) {
        if (!mesh.uvs[i].allFinite()) throw MeshLoadError(file, fmt::format("texture coordinate {}: not finite", i));
    }
    if (mesh.texture && mesh.uvs.empty()) throw MeshLoadError(file, "a texture but no texture coordinates");
}

void compute_vertex_normals(Mesh& mesh) {
    std::vector<Eigen::Vector3d> sum(mesh.positions.size(), Eigen::Vector3d::Zero());
    for (const auto& t : mesh.triangles) {
        if (t[0] >= sum.size() || t[1] >= sum.size() || t[2] >= sum.size()) continue;  // validate_mesh reports those
        const Eigen::Vector3d a = mesh.positions[t[0]].cast<double>();
        const Eigen::Vector3d b = mesh.positions[t[1]].cast<double>();
        const Eigen::Vector3d c = mesh.positions[t[2]].cast<double>();
        // The unnormalised cross product has length 2 * area: that is the area weighting.
        const Eigen::Vector3d w = (b - a).cross(c - a);
        for (const std::uint32_t v : t) sum[v] += w;
    }
    mesh.normals.resize(mesh.positions.size());
    for (std::size_t i = 0; i < sum.size(); ++i) {
        const double len = sum[i].norm();
        mesh.normals[i] = (len > 0.0 && std::isfinite(len)) ? Eigen::Vector3f((sum[i] / len).cast<float>())
                                                            : Eigen::Vector3f(0.f, 1.f, 0.f);
    }
}

Eigen::Vector3d recentre_mesh(Mesh& mesh) {
    if (mesh.positions.empty()) return std::exchange(mesh.origin, Eigen::Vector3d::Zero());
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    for (const Eigen::Vector3f& p : mesh.positions) {
        lo = lo.cwiseMin(p.cast<double>());
        hi = hi.cwiseMax(p.cast<double>());
    }
    const Eigen::Vector3d centre = 0.5 * (lo + hi);
    for (Eigen::Vector3f& p : mesh.positions) p = (p.cast<double>() - centre).cast<float>();
    const Eigen::Vector3d file_centre = mesh.origin + centre;
    mesh.origin = Eigen::Vector3d::Zero();
    return file_centre;
}

}  // namespace mogao
