// SPDX-License-Identifier: Apache-2.0
// The inverse of a projector's warp: for every content pixel, which output position lands on it.
//
// Method (per-projector inverse lookup by cell scan): the forward warp is the bilinear
// interpolation of the warp grid (warp_sampling.h), so between four neighbouring grid samples it
// is one bilinear patch from grid cell (s, t) in [0, 1]^2 to content (u, v). For every cell, the
// content pixel centres inside the patch's bounding box are tested: (s, t) is solved by Newton's
// method on the bilinear equations (exact in one step for an affine cell, as in the ideal
// calibration, where it reproduces the analytic inverse (u - u0) / b * W - 0.5), and the pixel is
// claimed when (s, t) lies in the cell (with 1e-9 slack so shared edges are not lost). The first
// cell to claim a pixel wins: a warp that folds over itself shows one layer. Cells with a NaN
// corner or a degenerate (zero-area) patch claim nothing.
//
// Coverage: the grid's samples span output positions grid_to_output(0) .. grid_to_output(M - 1)
// (pixel centres 0 .. W - 1 for a per-pixel grid), so the outer half pixel of the projector's
// image (plus, for a coarse grid, the edge band that reads a clamped edge sample) is not inverted;
// content there counts as uncovered. That is the projector's border, not a gap between
// projectors, whose overlaps cover it.
#pragma once

#include <vector>

#include "common/projector_calibration.h"

namespace mogao {

struct InverseWarp {
    ImageSize content;  // content frame size
    // Per content pixel (row-major, top row first): (x, y) output position in pixel-index
    // coordinates (pixel x's centre is x; add 0.5 for image coordinates), or NaN, NaN when no
    // output pixel of this projector lands there.
    std::vector<float> xy;
};

// Preconditions checked (std::invalid_argument): warp valid (validate_warp), output and content
// sizes valid, warp grid not finer than the output.
[[nodiscard]] InverseWarp build_inverse_warp(const WarpMap& warp, ImageSize output, ImageSize content);

}  // namespace mogao
