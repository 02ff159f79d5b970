// SPDX-License-Identifier: Apache-2.0
// A triangle mesh as loaded from a file, in the file's own units and frame.
//
// Shapes: positions.size() == normals.size() (or normals empty); triangles index positions,
// counter-clockwise seen from the front (the side the normal points to).
// Invariants after validate_mesh(): at least one triangle, every index < positions.size(),
// every coordinate finite.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace mogao {

struct Mesh {
    std::string source;                       // file path or procedural name, for messages
    std::vector<Eigen::Vector3f> positions;   // file units
    std::vector<Eigen::Vector3f> normals;     // unit per-vertex normals, or empty
    std::vector<std::array<std::uint32_t, 3>> triangles;

    [[nodiscard]] std::size_t triangle_count() const { return triangles.size(); }
};

}  // namespace mogao
