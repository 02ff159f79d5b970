// SPDX-License-Identifier: Apache-2.0
// How a warp or blend grid is read at an output pixel: the one CPU definition that the GL backend
// (drivers/egl, docs/outputs.md) implements in its shader (see projector_calibration.h).
//
// Grid convention (texel centres, as a GL texture): for an output of W pixels and a grid of M
// samples along one axis, output pixel x (centre x + 0.5) reads grid position
// g = (x + 0.5) * M / W - 0.5, sample k being at g = k; bilinear between samples, clamped to the
// first and last sample. A per-pixel grid (M = W) gives g = x exactly. For a coarse grid the
// outermost W / (2M) - 0.5 pixels on each side read the edge sample unchanged (e.g. 4.5 px for an
// MPCDI level-1 grid of a tenth of the resolution).
#pragma once

#include <array>

#include "common/projector_calibration.h"

namespace mogao {

// A content position, normalised (see projector_calibration.h). Both NaN = no content.
struct ContentUv {
    float u = 0.0F;
    float v = 0.0F;
    [[nodiscard]] bool valid() const { return !std::isnan(u) && !std::isnan(v); }
};

// Grid coordinate of output position x for `output_extent` output pixels and `grid_extent`
// samples. x is in pixel-index coordinates: pixel x's centre (image position x + 0.5) is x, and
// fractional values lie between centres. grid_to_output is the inverse.
[[nodiscard]] double output_to_grid(double x, int output_extent, int grid_extent);
[[nodiscard]] double grid_to_output(double g, int output_extent, int grid_extent);

// Bilinear warp at output pixel (x, y), x in [0, output.width). If a contributing sample (one with
// a non-zero bilinear weight) is NaN, the result is NaN, NaN: "no content" never blends into a
// neighbour's value. Preconditions: validate_warp passed, output non-empty.
[[nodiscard]] ContentUv sample_warp(const WarpMap& warp, ImageSize output, int x, int y);

// The same at a continuous output position in pixel-index coordinates (pixel x's centre is x;
// positions outside [0, W-1] clamp to the edge samples). Used by the inverse warp and its tests.
[[nodiscard]] ContentUv sample_warp_at(const WarpMap& warp, ImageSize output, double x, double y);

// Bilinear blend weight at output pixel (x, y). Preconditions: validate_blend passed.
[[nodiscard]] float sample_blend(const BlendMask& blend, ImageSize output, int x, int y);

// Bilinear black offset (beta) at output pixel (x, y), per channel, same grid convention as the
// blend; an empty offset (0 x 0) gives 0. Preconditions: validate_beta passed.
[[nodiscard]] std::array<float, 3> sample_beta(const BlackOffset& beta, ImageSize output, int x, int y);

}  // namespace mogao
