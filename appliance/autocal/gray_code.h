// SPDX-License-Identifier: Apache-2.0
// Gray-code structured light for one projector (autocal.h, step 1): shows white, black and the
// Gray-code patterns with their inverses through a PatternSource, decodes per camera pixel and
// returns one correspondence per fully seen cell of projector pixels.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "appliance/autocal/autocal.h"

namespace mogao::autocal {

struct Correspondences {
    std::vector<cv::Point2d> camera;     // camera image positions (pixel centre +0.5)
    std::vector<cv::Point2d> projector;  // projector image positions: centres of the decoded blocks
    std::vector<cv::Point2d> block;      // the blocks' width and height, projector pixels
    int column_bits = 0;                 // Gray bits resolved per axis
    int row_bits = 0;
    int lit_pixels = 0;  // camera pixels over the shadow-mask contrast
    int captures = 0;    // camera images taken
};

// Projector k of `projectors` (their resolutions) is decoded; the others stay black.
[[nodiscard]] Correspondences decode_projector(PatternSource& source, int k, const std::vector<ImageSize>& projectors,
                                               const AutocalOptions& options);

}  // namespace mogao::autocal
