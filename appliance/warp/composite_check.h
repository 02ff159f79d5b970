// SPDX-License-Identifier: Apache-2.0
// Measures for "does the composite equal the content": per-pixel differences inside a region and
// the seam measure across a content column. Used by the tests and by the calibration CLI's report.
#pragma once

#include "common/image.h"
#include "common/pixel_rect.h"

namespace mogao {

struct ImageDifference {
    double max_abs = 0.0;   // largest |a - b| over the region's pixels and channels
    double mean_abs = 0.0;  // mean |a - b| over the region's pixels and channels
    int max_x = -1;         // where max_abs occurs (first occurrence), -1 for an empty region
    int max_y = -1;
};

// Compares a and b (same size, linear values) over `region` clipped to the image.
// Throws std::invalid_argument when the sizes differ or an image is malformed.
[[nodiscard]] ImageDifference compare_images(const RgbFloatImage& a, const RgbFloatImage& b, PixelRect region);

// Seam measure at content column `column` (1 <= column < width): the largest change, over rows
// [row0, row1) and channels, of the error e = composite - content between column - 1 and column.
// A correct blend has no step in e; a seam (weights not summing to 1 on one side) shows as one.
[[nodiscard]] double seam_step(const RgbFloatImage& composite, const RgbFloatImage& content, int column, int row0,
                               int row1);

}  // namespace mogao
