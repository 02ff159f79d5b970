// SPDX-License-Identifier: Apache-2.0
// The scene as our renderer sees it, written for another renderer (Blender Cycles, bench/peer/cycles_scene.py):
//
//  * OBJ + MTL (Wavefront): every instance's triangles in WORLD coordinates (metres, right-handed,
//    +y up, as scene.h), after loading: mesh units, re-centring, transforms and ring instancing
//    applied, one `o`/`usemtl` group per instance, per-vertex normals (`vn`, transformed by the
//    inverse transpose) where the mesh has them. Positions are written in double precision from
//    origin + position, so nothing is lost to the float narrowing of the file. A textured mesh's
//    texture coordinates (`vt`, v flipped to OBJ's up-the-image convention) and its base-colour
//    texture (texture<mesh>.png, the loaded sRGB8 level 0) are written, the instance's material then
//    named <material>__texture<mesh> with `map_Kd`. Vertex colours are NOT written (a scene using
//    them differs; peer.json lists those meshes).
//  * peer.json: camera (pinhole vertical fov, eye, the camera-to-world rotation R = Ry(yaw) Rx(pitch)
//    of renderfarm/trace/camera.h, columns right/up/back), size, materials (albedo, specular k_s, GGX
//    alpha = sqrt(2 / (s + 2)) as renderfarm/trace/shading.h), lights in our units (point intensity
//    W/sr, sun irradiance W/m^2, area radiance W/(sr m^2) with corner and edges, environment
//    radiance), exposure and tone map, the textured materials' texture file and wrap modes, plus the
//    meshes carrying vertex colours.
#pragma once

#include <filesystem>
#include <set>
#include <string>

#include <Eigen/Core>

#include "common/result.h"
#include "common/view_request.h"
#include "renderfarm/scene/scene.h"

namespace mogao::peer {

struct ExportStats {
    std::size_t triangles = 0;  // summed over instances
    std::size_t vertices = 0;
    std::size_t uvs = 0;                     // `vt` lines
    std::set<std::size_t> textures_written;  // meshes whose texture<mesh>.png was written
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = Eigen::Vector3d::Constant(-1e300);  // world bounds
};

// Writes <dir>/scene.obj and <dir>/scene.mtl. Errors: errno naming the file.
[[nodiscard]] Result<ExportStats> write_obj(const Scene& scene, const std::filesystem::path& dir);

// Writes <dir>/peer.json for a pinhole request (std::invalid_argument for a cylinder camera: Cycles has
// no cylindrical-screen camera).
[[nodiscard]] Status write_peer_json(const Scene& scene, const ViewRequest& request, const std::filesystem::path& dir);

// Reads back the `v`, `vt` and `f` lines of an OBJ (triangles only, 1-based indices, `v/vt/vn` forms), for
// the round-trip test: triangle, vertex and texture-coordinate counts and the bounds.
[[nodiscard]] Result<ExportStats> read_obj_stats(const std::filesystem::path& file);

}  // namespace mogao::peer
