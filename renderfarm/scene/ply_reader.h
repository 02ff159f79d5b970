// SPDX-License-Identifier: Apache-2.0
// Our own PLY reader (used by load_mesh for ".ply"). We need the header anyway to see whether the
// faces come as a `tristrips` element, and Debian 12's assimp 5.2.5 reads that layout silently
// wrong (igea.ply becomes one triangle), so we parse the whole format ourselves.
//
// Supported: format ascii / binary_little_endian / binary_big_endian 1.0; property types
// char/int8 uchar/uint8 short/int16 ushort/uint16 int/int32 uint/uint32 float/float32 double/float64.
// Elements: `vertex` (x, y, z required, nx, ny, nz optional), `face` (list vertex_indices or
// vertex_index; polygons fan-triangulated), `tristrips` (list vertex_indices, -1 ends a strip,
// winding alternates, degenerate triangles skipped). Any other element or property is skipped by
// its declared types. Anything else (unknown type or format, truncated data, an index out of
// range, a list longer than kMaxPlyListLength) throws MeshLoadError.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "renderfarm/scene/mesh.h"

namespace mogao {

// Longest list we accept in one property (sanity limit against corrupt counts; igea.ply's single
// tristrips list has 373,830 items).
inline constexpr std::uint64_t kMaxPlyListLength = std::uint64_t{1} << 26;

// Parses a whole PLY file held in memory. `name` is used in error messages and as mesh.source.
// The result is not validated (load_mesh does that).
[[nodiscard]] Mesh parse_ply(std::string_view bytes, const std::string& name);

// Reads the file and calls parse_ply.
[[nodiscard]] Mesh read_ply(const std::filesystem::path& path);

}  // namespace mogao
