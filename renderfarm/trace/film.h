// SPDX-License-Identifier: Apache-2.0
// Linear radiance -> display 8-bit sRGB for a rect of a frame.
//
// Per channel: v = clamp(exposure * L, 0, 1) (NaN -> 0), then the sRGB OETF of IEC 61966-2-1:
//   V = 12.92 v                      for v <= 0.0031308
//   V = 1.055 v^(1/2.4) - 0.055      otherwise,
// stored as round-to-nearest(255 V) (evaluated exactly via 255 precomputed code thresholds in
// linear space). Only pixels inside rect are written.
// Throws std::invalid_argument if in.size != out.size, rect is not inside the image, or exposure
// is negative or not finite.
#pragma once

#include <cstdint>

#include "common/image.h"
#include "common/pixel_rect.h"

namespace mogao {

// One channel: linear value (already exposed) -> 8-bit sRGB code.
[[nodiscard]] std::uint8_t encode_srgb8(float linear);

void to_srgb8(const RgbFloatImage& in, const PixelRect& rect, float exposure, Rgb8Image& out);

}  // namespace mogao
