// SPDX-License-Identifier: Apache-2.0
// A triangle mesh as loaded from a file, in the file's own units and frame.
//
// Shapes: normals, colors and uvs each hold positions.size() entries or none; triangles index
// positions, counter-clockwise seen from the front (the side the normal points to).
// Precision: positions are float offsets from `origin` (double, file units): readers parse in
// double and subtract the bounding-box centre before narrowing, so a scan 1e6 units from its
// file's origin keeps sub-millimetre detail; recentre_mesh folds origin into the instance.
// Invariants after validate_mesh(): at least one triangle, every index < positions.size(),
// every coordinate finite.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "renderfarm/scene/texture.h"

namespace mogao {

struct Mesh {
    std::string source;                                // file path or procedural name, for messages
    Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // file units; positions are relative to it
    std::vector<Eigen::Vector3f> positions;            // file units, relative to origin
    std::vector<Eigen::Vector3f> normals;              // unit per-vertex normals, or empty
    std::vector<Eigen::Vector3f> colors;               // linear RGB in [0, 1] per vertex (from sRGB), or empty
    std::vector<Eigen::Vector2f> uvs;                  // texture coordinates per vertex (glTF/OpenGL-image
                                                       // convention as assimp gives them: (0,0) = first
                                                       // texel row's left edge after its v flip), or empty
    std::shared_ptr<const Texture> texture;            // base colour, with uvs; null when none
    std::vector<std::array<std::uint32_t, 3>> triangles;

    [[nodiscard]] std::size_t triangle_count() const { return triangles.size(); }
};

}  // namespace mogao
