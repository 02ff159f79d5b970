// SPDX-License-Identifier: Apache-2.0
// load_mesh: dispatch by extension to our PLY reader or assimp, then validate and tidy normals.
// validate_mesh / compute_vertex_normals / recentre_mesh live in mesh_validate.cpp.
#include "renderfarm/scene/mesh_io.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <sstream>
#include <system_error>
#include <utility>
#include <vector>

#include <Eigen/Dense>
#include <assimp/DefaultIOSystem.h>
#include <assimp/Importer.hpp>
#include <assimp/MemoryIOWrapper.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

#include "common/srgb.h"
#include "renderfarm/scene/ply_reader.h"
#include "renderfarm/scene/texture_io.h"

namespace mogao {

MeshLoadError::MeshLoadError(const std::string& file, const std::string& reason)
    : std::runtime_error(file + ": " + reason), file_(file), reason_(reason) {}

namespace {

std::string lower_extension(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext;
}

Eigen::Matrix4d to_eigen(const aiMatrix4x4& m) {
    Eigen::Matrix4d r;
    r << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3, m.d4;
    return r;
}

// Which optional per-vertex attributes every appended aiMesh had (all-or-nothing, mesh.h).
struct Attributes {
    bool normals = true;
    bool colors = true;
    bool uvs = true;
};

float srgb_to_linear(float v) {
    const double c = std::clamp(static_cast<double>(v), 0.0, 1.0);
    return static_cast<float>(srgb_decode(c));
}

// Appends the triangles of one aiMesh placed by `to_file` (the node's accumulated transform).
// Colours: glTF COLOR_0 is linear by the glTF 2.0 spec (§3.7.2.1); other formats' colours are
// display sRGB and are decoded. UVs are channel 0.
void append_mesh(Mesh& out, const aiMesh& in, const Eigen::Matrix4d& to_file, const std::string& file,
                 bool linear_colors, Attributes& has) {
    const std::size_t base = out.positions.size();
    if (base + in.mNumVertices > std::numeric_limits<std::uint32_t>::max()) {
        throw MeshLoadError(file, "more vertices than 32-bit indices can address");
    }
    const Eigen::Matrix3d linear = to_file.topLeftCorner<3, 3>();
    // Normals transform by the inverse transpose; a singular transform keeps the linear part
    // (the normals get renormalised later anyway).
    const Eigen::Matrix3d normal_matrix =
        std::abs(linear.determinant()) > 0.0 ? Eigen::Matrix3d(linear.inverse().transpose()) : linear;
    for (unsigned v = 0; v < in.mNumVertices; ++v) {
        const aiVector3D& p = in.mVertices[v];
        const Eigen::Vector4d q = to_file * Eigen::Vector4d(p.x, p.y, p.z, 1.0);
        out.positions.push_back(q.head<3>().cast<float>());
        if (in.HasNormals()) {
            const aiVector3D& n = in.mNormals[v];
            out.normals.push_back((normal_matrix * Eigen::Vector3d(n.x, n.y, n.z)).cast<float>());
        }
        if (in.HasVertexColors(0)) {
            const aiColor4D& c = in.mColors[0][v];
            const auto channel = [&](float x) { return linear_colors ? std::clamp(x, 0.0f, 1.0f) : srgb_to_linear(x); };
            out.colors.emplace_back(channel(c.r), channel(c.g), channel(c.b));
        }
        if (in.HasTextureCoords(0)) out.uvs.emplace_back(in.mTextureCoords[0][v].x, in.mTextureCoords[0][v].y);
    }
    for (unsigned f = 0; f < in.mNumFaces; ++f) {
        const aiFace& face = in.mFaces[f];
        if (face.mNumIndices != 3) continue;  // points and lines left after triangulation
        out.triangles.push_back({static_cast<std::uint32_t>(base + face.mIndices[0]),
                                 static_cast<std::uint32_t>(base + face.mIndices[1]),
                                 static_cast<std::uint32_t>(base + face.mIndices[2])});
    }
    has.normals = has.normals && in.HasNormals();
    has.colors = has.colors && in.HasVertexColors(0);
    has.uvs = has.uvs && in.HasTextureCoords(0);
}

// Vertex numbers here are assimp's, before joining (for OBJ: one per face corner); the
// coordinates in the message help find the line.
void check_finite(const aiScene& scene, const std::string& file) {
    for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
        const aiMesh& mesh = *scene.mMeshes[m];
        for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
            const aiVector3D& p = mesh.mVertices[v];
            if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
                throw MeshLoadError(
                    file, fmt::format("mesh {} vertex {}: coordinate is not finite ({}, {}, {})", m, v, p.x, p.y, p.z));
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

// OBJ text with every vertex line "v x y z ..." rewritten relative to the bounding-box centre of
// all vertex lines, computed in double. assimp (Debian's build: ai_real = float) then parses
// small offsets instead of large absolute coordinates. Lines that do not parse stay as they are
// (assimp reports them).
struct RecentredObj {
    std::string text;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
};

bool parse_vertex_line(std::string_view line, Eigen::Vector3d& p, std::size_t& rest) {
    if (line.size() < 2 || line[0] != 'v' || (line[1] != ' ' && line[1] != '\t')) return false;
    std::size_t pos = 1;
    for (int k = 0; k < 3; ++k) {
        while (pos < line.size() && (line[pos] == ' ' || line[pos] == '\t')) ++pos;
        const auto r = std::from_chars(line.data() + pos, line.data() + line.size(), p[k]);
        if (r.ec != std::errc{}) return false;
        pos = static_cast<std::size_t>(r.ptr - line.data());
    }
    rest = pos;
    return p.allFinite();
}

RecentredObj recentre_obj_text(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream buffer;
    buffer << in.rdbuf();
    const std::string text = buffer.str();
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    std::size_t rest = 0;
    Eigen::Vector3d p;
    for (std::size_t start = 0; start < text.size();) {
        const std::size_t end = std::min(text.find('\n', start), text.size());
        if (parse_vertex_line(std::string_view(text).substr(start, end - start), p, rest)) {
            lo = lo.cwiseMin(p);
            hi = hi.cwiseMax(p);
        }
        start = end + 1;
    }
    RecentredObj out;
    if (!(lo.x() <= hi.x())) {
        out.text = text;
        return out;
    }
    out.centre = 0.5 * (lo + hi);
    out.text.reserve(text.size() + text.size() / 8);
    for (std::size_t start = 0; start < text.size();) {
        const std::size_t end = std::min(text.find('\n', start), text.size());
        const std::string_view line = std::string_view(text).substr(start, end - start);
        if (parse_vertex_line(line, p, rest)) {
            const Eigen::Vector3d q = p - out.centre;
            out.text += fmt::format("v {:.17g} {:.17g} {:.17g}", q.x(), q.y(), q.z());
            out.text += line.substr(rest);
        } else {
            out.text += line;
        }
        if (end < text.size()) out.text += '\n';
        start = end + 1;
    }
    return out;
}

// Serves the re-centred OBJ text for the main file; every other file (.mtl, textures) from disk.
class RecentredObjIOSystem : public Assimp::DefaultIOSystem {
public:
    RecentredObjIOSystem(std::string file, const std::string& text) : file_(std::move(file)), text_(text) {}
    Assimp::IOStream* Open(const char* file, const char* mode) override {
        if (file_ == file)
            return new Assimp::MemoryIOStream(reinterpret_cast<const std::uint8_t*>(text_.data()), text_.size());
        return Assimp::DefaultIOSystem::Open(file, mode);
    }

private:
    std::string file_;
    const std::string& text_;
};

const aiScene* import_scene(Assimp::Importer& importer, const std::filesystem::path& path) {
    const std::string file = path.string();
    const std::string ext = lower_extension(path);
    if (ext.empty() || !importer.IsExtensionSupported(ext)) {
        throw MeshLoadError(file, fmt::format("unsupported file extension '{}'", ext));
    }
    // Triangulate polygons; UVs with (0, 0) at the image's top-left (texture.h). No normal
    // generation or smoothing: we keep what the file has.
    const aiScene* scene = importer.ReadFile(file, aiProcess_Triangulate | aiProcess_FlipUVs);
    if (scene == nullptr) throw MeshLoadError(file, fmt::format("assimp: {}", importer.GetErrorString()));
    // Checked before joining: JoinIdenticalVertices silently merges a NaN vertex into another one.
    check_finite(*scene, file);
    // Join identical vertices because the OBJ importer emits one vertex per face corner (3x the
    // memory, and no shared vertices to smooth normals over).
    scene = importer.ApplyPostProcessing(aiProcess_JoinIdenticalVertices);
    if (scene == nullptr) throw MeshLoadError(file, fmt::format("assimp: {}", importer.GetErrorString()));
    return scene;
}

Mesh read_with_assimp(const std::filesystem::path& path) {
    const std::string file = path.string();
    const std::string ext = lower_extension(path);
    RecentredObj obj;  // outlives the importer, which reads it through the IO handler
    Assimp::Importer importer;
    if (ext == ".obj") {
        obj = recentre_obj_text(path);
        importer.SetIOHandler(new RecentredObjIOSystem(file, obj.text));  // the importer owns it
    }
    const aiScene* scene = import_scene(importer, path);

    Mesh mesh;
    mesh.source = file;
    mesh.origin = obj.centre;  // OBJ has no node transforms: the file frame is the mesh frame
    Attributes has;
    const bool linear_colors = ext == ".gltf" || ext == ".glb";
    std::vector<unsigned> materials;
    // Iterative walk: a hostile file must not be able to overflow the stack with deep nesting.
    std::vector<std::pair<const aiNode*, Eigen::Matrix4d>> stack;
    if (scene->mRootNode != nullptr) stack.emplace_back(scene->mRootNode, Eigen::Matrix4d::Identity());
    while (!stack.empty()) {
        auto [node, parent] = stack.back();
        stack.pop_back();
        const Eigen::Matrix4d to_file = parent * to_eigen(node->mTransformation);
        for (unsigned k = 0; k < node->mNumMeshes; ++k) {
            if (node->mMeshes[k] >= scene->mNumMeshes)
                throw MeshLoadError(file, "assimp: node refers to a missing mesh");
            const aiMesh& part = *scene->mMeshes[node->mMeshes[k]];
            append_mesh(mesh, part, to_file, file, linear_colors, has);
            materials.push_back(part.mMaterialIndex);
        }
        for (unsigned c = 0; c < node->mNumChildren; ++c) stack.emplace_back(node->mChildren[c], to_file);
    }
    // Normals, colours and UVs are all-or-nothing per mesh.h: a file where only some parts have
    // them gets none.
    if (!has.normals) mesh.normals.clear();
    if (!has.colors) mesh.colors.clear();
    if (!has.uvs) mesh.uvs.clear();
    if (!mesh.uvs.empty()) mesh.texture = load_base_color_texture(*scene, materials, path);
    if (!mesh.texture) mesh.uvs.clear();  // UVs without a texture are of no use to the renderer
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
