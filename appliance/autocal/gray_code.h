// SPDX-License-Identifier: Apache-2.0
// Gray-code structured light for one projector (autocal.h, step 1): shows white, black and the
// Gray-code patterns with their inverses through a PatternSource, decodes per camera pixel, refines
// the positions by phase shifting where options.phase_shifts > 0 (phase_shift.h) and returns one
// correspondence per decoded camera pixel (evenly strided down to options.max_correspondences).
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "appliance/autocal/autocal.h"

namespace mogao::autocal {

struct Correspondences {
    std::vector<cv::Point2d> camera;     // camera image positions (pixel centre +0.5)
    std::vector<cv::Point2d> projector;  // projector image positions: phase-refined, else the decoded block's centre
    std::vector<cv::Point2d> sigma;      // their uncertainty per axis, projector pixels (block / sqrt(12) for a
                                         // block centre, phase_shift.h's sigma_X for a refined position)
    int column_bits = 0;                 // Gray bits resolved per axis
    int row_bits = 0;
    int lit_pixels = 0;             // camera pixels over the shadow mask
    int phase_refined_columns = 0;  // lit camera pixels whose column / row the phase refined
    int phase_refined_rows = 0;
    double noise_sigma = 0.0;       // estimated noise of one black camera image (camera units)
    double shadow_threshold = 0.0;  // the shadow mask's white - black threshold it gave
    int captures = 0;               // camera images taken
};

// Projector k of `projectors` (their resolutions) is decoded; the others stay black.
[[nodiscard]] Correspondences decode_projector(PatternSource& source, int k, const std::vector<ImageSize>& projectors,
                                               const AutocalOptions& options);

}  // namespace mogao::autocal
