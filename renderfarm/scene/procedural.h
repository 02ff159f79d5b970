// SPDX-License-Identifier: Apache-2.0
// Procedural meshes named in scene files ("procedural": "<kind>"): the grotto room the scans stand
// in, pedestals, and analytic test shapes. All in metres, +y up, counter-clockwise front faces.
//
// Each generator validates its parameters and throws std::invalid_argument naming the parameter and
// its limit (the scene reader turns it into a SceneError naming the file and field).
#pragma once

#include <cstdint>

#include "renderfarm/scene/mesh.h"

namespace mogao {

// A cave-like room: a floor disc, a wall around it whose radius varies smoothly with angle and
// height (deterministic value noise, amplitude `roughness` * radius), a domed ceiling, and an
// entrance gap of `entrance_deg` centred on +z (where the sun comes in). Faces point inward.
struct GrottoRoomParams {
    double radius = 7.0;         // metres, (0.5, 1000]
    double height = 5.0;         // wall height before the dome, (0.5, 1000]
    double dome_height = 2.0;    // [0, 1000]
    double entrance_deg = 40.0;  // [0, 180)
    int segments = 512;          // around the axis, [8, 65536]
    int rings = 128;             // up the wall, [1, 65536]
    double roughness = 0.03;     // [0, 0.2]
    std::uint32_t seed = 7;
};
[[nodiscard]] Mesh make_grotto_room(const GrottoRoomParams& params);

// Axis-aligned box centred on the origin with the given full extents (metres), faces outward.
[[nodiscard]] Mesh make_box(double size_x, double size_y, double size_z);

// UV sphere of `radius` centred on the origin with exact per-vertex normals.
[[nodiscard]] Mesh make_uv_sphere(double radius, int segments, int rings);

// Flat square in the xz plane at y=0, side `size`, normal +y, subdivided n x n.
[[nodiscard]] Mesh make_ground_plane(double size, int subdivisions);

}  // namespace mogao
