// SPDX-License-Identifier: Apache-2.0
// Mesh loading for the scene stage: our own PLY reader for .ply, assimp for everything else.
// Every loaded mesh is validated (validate_mesh) before it is returned, so callers can rely on the
// invariants in mesh.h. Details, error messages and measured load times: docs/mesh-loading.md.
#pragma once

#include <cstddef>
#include <filesystem>
#include <stdexcept>
#include <string>

#include <Eigen/Core>

#include "renderfarm/scene/mesh.h"

namespace mogao {

// Any reason a mesh file cannot be used. what() is "<file>: <reason>", where the reason names the
// element/line/index and the limit involved, e.g.
// "igea.ply: face 12: vertex index 99999 out of range (134345 vertices)".
class MeshLoadError : public std::runtime_error {
public:
    MeshLoadError(const std::string& file, const std::string& reason);
    [[nodiscard]] const std::string& file() const { return file_; }
    [[nodiscard]] const std::string& reason() const { return reason_; }

private:
    std::string file_;
    std::string reason_;
};

// What load_mesh did, for logs and the load-time table in docs/mesh-loading.md.
struct MeshLoadReport {
    std::size_t triangles = 0;
    std::size_t vertices = 0;
    double seconds = 0.0;  // wall time of read + parse + validate
    std::string loader;    // "ply" (ours) or "assimp"
};

// Loads a triangle mesh in the file's own units and frame. Extension ".ply" (any case) uses our
// PLY reader (ascii / binary, faces and tristrips); any other extension goes through assimp, with
// all meshes of the file merged into one and node transforms applied. Normals are kept only when
// the file has them for every vertex (then normalised); otherwise mesh.normals is empty and the
// caller may call compute_vertex_normals. mesh.source is set to `path`.
// Throws MeshLoadError for a missing file, an unsupported extension, malformed or truncated data,
// or a mesh that fails validate_mesh. If `report` is non-null it is filled on success.
[[nodiscard]] Mesh load_mesh(const std::filesystem::path& path, MeshLoadReport* report = nullptr);

// Throws MeshLoadError (file = mesh.source) when the mesh breaks the invariants of mesh.h: no
// triangles, an index out of range, a non-finite position or normal, or a normals count that is
// neither 0 nor positions.size().
void validate_mesh(const Mesh& mesh);

// Replaces mesh.normals with area-weighted smooth vertex normals. A vertex with no (or only
// degenerate) adjacent area gets (0, 1, 0), so the result is always finite and unit length.
void compute_vertex_normals(Mesh& mesh);

// Moves the mesh so its bounding-box centre is at the origin and returns that centre in file
// units (computed in double). The caller folds it into the instance transform, which keeps float
// coordinates small for scans whose origin is far away. An empty mesh is left as is (returns 0).
Eigen::Vector3d recentre_mesh(Mesh& mesh);

}  // namespace mogao
