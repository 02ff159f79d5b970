// SPDX-License-Identifier: Apache-2.0
// Procedural meshes and scenes for the trace tests, built in code (no scene files).
#pragma once

#include <Eigen/Core>

#include "common/view_request.h"
#include "renderfarm/scene/mesh.h"
#include "renderfarm/scene/scene.h"

namespace mogao::test {

// Flat square [-half, half]² in the y = 0 plane, n x n cells of two triangles, facing +y,
// optionally with (+y) vertex normals.
[[nodiscard]] Mesh make_grid(int n, float half, bool with_normals);

// Sphere of radius 0.5 at (0, 1, 0) (smooth) over a 4 x 4 m grid at y = 0, translated by
// `offset`, materials: 0 = grey 0.5, 1 = glossy. No lights.
[[nodiscard]] Scene make_sphere_over_floor(const Eigen::Vector3d& offset = Eigen::Vector3d::Zero());

// A pinhole request looking from `eye` at `target`.
[[nodiscard]] ViewRequest look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, ImageSize size,
                                  double fov_deg);

}  // namespace mogao::test
