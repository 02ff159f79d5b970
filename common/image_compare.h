// SPDX-License-Identifier: Apache-2.0
// Image comparison metrics for codec tests, the quality benchmark and multi-rank == single-rank
// checks. All functions throw std::invalid_argument if the images differ in size or are malformed.
#pragma once

#include <cstdint>

#include "common/image.h"

namespace mogao {

// Peak signal-to-noise ratio in dB over all R, G, B samples with peak 255:
// 10 * log10(255^2 / MSE). +infinity when the images are identical.
[[nodiscard]] double psnr(const Rgb8Image& a, const Rgb8Image& b);

// Largest |a - b| over all samples (0..255), as a double for uniformity with psnr.
[[nodiscard]] double max_abs_difference(const Rgb8Image& a, const Rgb8Image& b);

// Pixels where at least one channel differs by more than `tolerance` (0 = any difference).
[[nodiscard]] std::int64_t count_differing_pixels(const Rgb8Image& a, const Rgb8Image& b, int tolerance = 0);

}  // namespace mogao
