// SPDX-License-Identifier: Apache-2.0
// load_mesh: dispatch by extension to our PLY reader or assimp, then validate and tidy normals.
// validate_mesh / compute_vertex_normals / recentre_mesh live in mesh_validate.cpp.
#include "renderfarm/scene/mesh_io.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <system_error>
#include <utility>
#include <vector>

#include <Eigen/Dense>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

#include "renderfarm/scene/ply_reader.h"

namespace mogao {

MeshLoadError::MeshLoadError(const std::string& file, const std::string& reason)
    : std::runtime_error(file + ": " + reason), file_(file), reason_(reason) {}

namespace {

std::string lower_extension(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext;
}

Eigen::Matrix4d to_eigen(const aiMatrix4x4& m) {
    Eigen::Matrix4d r;
    r << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3, m.d4;
    return r;
}

// Appends the triangles of one aiMesh placed by `to_file` (the node's accumulated transform).
// Returns false when the mesh has no normals.
bool append_mesh(Mesh& out, const aiMesh& in, const Eigen::Matrix4d& to_file, const std::string& file) {
    const std::size_t base = out.positions.size();
    if (base + in.mNumVertices > std::numeric_limits<std::uint32_t>::max()) {
        throw MeshLoadError(file, "more vertices than 32-bit indices can address");
    }
    const Eigen::Matrix3d linear = to_file.topLeftCorner<3, 3>();
    // Normals transform by the inverse transpose; a singular transform keeps the linear part
    // (the normals get renormalised later anyway).
    const Eigen::Matrix3d normal_matrix = std::abs(linear.determinant()) > 0.0 ? Eigen::Matrix3d(linear.inverse().transpose()) : linear;
    for (unsigned v = 0; v < in.mNumVertices; ++v) {
        const aiVector3D& p = in.mVertices[v];
        const Eigen::Vector4d q = to_file * Eigen::Vector4d(p.x, p.y, p.z, 1.0);
        out.positions.push_back(q.head<3>().cast<float>());
        if (in.HasNormals()) {
            const aiVector3D& n = in.mNormals[v];
            out.normals.push_back((normal_matrix * Eigen::Vector3d(n.x, n.y, n.z)).cast<float>());
        }
    }
    for (unsigned f = 0; f < in.mNumFaces; ++f) {
        const aiFace& face = in.mFaces[f];
        if (face.mNumIndices != 3) continue;  // points and lines left after triangulation
        out.triangles.push_back({static_cast<std::uint32_t>(base + face.mIndices[0]), static_cast<std::uint32_t>(base + face.mIndices[1]),
                                 static_cast<std::uint32_t>(base + face.mIndices[2])});
    }
    return in.HasNormals();
}

// Vertex numbers here are assimp's, before joining (for OBJ: one per face corner); the
// coordinates in the message help find the line.
void check_finite(const aiScene& scene, const std::string& file) {
    for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
        const aiMesh& mesh = *scene.mMeshes[m];
        for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
            const aiVector3D& p = mesh.mVertices[v];
            if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
                throw MeshLoadError(file, fmt::format("mesh {} vertex {}: coordinate is not finite ({}, {}, {})", m, v, p.x, p.y, p.z));
            }
            if (mesh.HasNormals()) {
                const aiVector3D& n = mesh.mNormals[v];
                if (!std::isfinite(n.x) || !std::isfinite(n.y) || !std::isfinite(n.z)) {
                    throw MeshLoadError(file, fmt::format("mesh {} normal {}: not finite", m, v));
                }
            }
        }
    }
}

Mesh read_with_assimp(const std::filesystem::path& path) {
    const std::string file = path.string();
    Assimp::Importer importer;
    const std::string ext = lower_extension(path);
    if (ext.empty() || !importer.IsExtensionSupported(ext)) {
        throw MeshLoadError(file, fmt::format("unsupported file extension '{}'", ext));
    }
    // Triangulate polygons. No normal generation or smoothing: we keep what the file has.
    const aiScene* scene = importer.ReadFile(file, aiProcess_Triangulate);
    if (scene == nullptr) throw MeshLoadError(file, fmt::format("assimp: {}", importer.GetErrorString()));
    // Checked before joining: JoinIdenticalVertices silently merges a NaN vertex into another one.
    check_finite(*scene, file);
    // Join identical vertices because the OBJ importer emits one vertex per face corner (3x the
    // memory, and no shared vertices to smooth normals over).
    scene = importer.ApplyPostProcessing(aiProcess_JoinIdenticalVertices);
    if (scene == nullptr) throw MeshLoadError(file, fmt::format("assimp: {}", importer.GetErrorString()));

    Mesh mesh;
    mesh.source = file;
    bool all_normals = true;
    // Iterative walk: a hostile file must not be able to overflow the stack with deep nesting.
    std::vector<std::pair<const aiNode*, Eigen::Matrix4d>> stack;
    if (scene->mRootNode != nullptr) stack.emplace_back(scene->mRootNode, Eigen::Matrix4d::Identity());
    while (!stack.empty()) {
        auto [node, parent] = stack.back();
        stack.pop_back();
        const Eigen::Matrix4d to_file = parent * to_eigen(node->mTransformation);
        for (unsigned k = 0; k < node->mNumMeshes; ++k) {
            if (node->mMeshes[k] >= scene->mNumMeshes) throw MeshLoadError(file, "assimp: node refers to a missing mesh");
            all_normals = append_mesh(mesh, *scene->mMeshes[node->mMeshes[k]], to_file, file) && all_normals;
        }
        for (unsigned c = 0; c < node->mNumChildren; ++c) stack.emplace_back(node->mChildren[c], to_file);
    }
    // Normals are all-or-nothing per mesh.h; a file where only some parts have them gets none.
    if (!all_normals) mesh.normals.clear();
    return mesh;
}

// File normals need not be unit length. A zero-length one has no direction at all, so then the
// whole set is replaced by computed normals rather than guessing per vertex.
void normalise_file_normals(Mesh& mesh) {
    for (Eigen::Vector3f& n : mesh.normals) {
        const double len = n.cast<double>().norm();
        if (!(len > 1e-30)) {
            compute_vertex_normals(mesh);
            return;
        }
        n = (n.cast<double>() / len).cast<float>();
    }
}

}  // namespace

Mesh load_mesh(const std::filesystem::path& path, MeshLoadReport* report) {
    const auto start = std::chrono::steady_clock::now();
    const std::string file = path.string();
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw MeshLoadError(file, "file not found");
    if (!std::filesystem::is_regular_file(path, ec)) throw MeshLoadError(file, "not a regular file");

    const bool ply = lower_extension(path) == ".ply";
    Mesh mesh = ply ? read_ply(path) : read_with_assimp(path);
    validate_mesh(mesh);
    normalise_file_normals(mesh);

    if (report != nullptr) {
        report->triangles = mesh.triangles.size();
        report->vertices = mesh.positions.size();
        report->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        report->loader = ply ? "ply" : "assimp";
    }
    return mesh;
}

}  // namespace mogao
