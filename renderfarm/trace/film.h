// SPDX-License-Identifier: Apache-2.0
// Linear radiance -> display 8-bit sRGB for a rect of a frame.
//
// Per channel: x = exposure * L (NaN and negative -> 0), v = T(x) with the scene's tone map T,
//   clamp:    T(x) = min(x, 1)                     highlights above 1 clip flat
//   reinhard: T(x) = x / (1 + x)                    Reinhard et al., "Photographic Tone
//             Reproduction for Digital Images", SIGGRAPH 2002, eq. 3 (applied per channel)
//   aces:     T(x) = clamp(x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14), 0, 1)
//             K. Narkowicz, "ACES Filmic Tone Mapping Curve", 2015 (a fit of the ACES RRT + sRGB
//             ODT; the post scales x by 0.6 first to match ACES brightness, we leave that to
//             `exposure`)
// then the sRGB OETF of IEC 61966-2-1:
//   V = 12.92 v                      for v <= 0.0031308
//   V = 1.055 v^(1/2.4) - 0.055      otherwise,
// stored as round-to-nearest(255 V) (evaluated exactly via 255 precomputed code thresholds in
// linear space, reached through a lookup table indexed by the float's top bits, film.cpp). Only pixels inside rect are
// written. Throws std::invalid_argument if in.size != out.size, rect is not inside the image, or exposure is negative
// or not finite.
#pragma once

#include <cstdint>
#include <string>

#include "common/image.h"
#include "common/pixel_rect.h"
#include "renderfarm/scene/scene.h"

namespace mogao {

// One channel: linear value in [0, 1] (already exposed and tone-mapped) -> 8-bit sRGB code;
// values outside [0, 1] clamp, NaN gives 0.
[[nodiscard]] std::uint8_t encode_srgb8(float linear);

// T(x) of the list above, for x >= 0.
[[nodiscard]] float tone_map(ToneMap op, float x);

// "clamp" | "reinhard" | "aces" -> ToneMap; std::invalid_argument naming the allowed names.
[[nodiscard]] ToneMap parse_tone_map(const std::string& name);
[[nodiscard]] const char* tone_map_name(ToneMap op);

// `threads`: row bands of rect run on this many threads (0 = std::thread::hardware_concurrency; the
// same bytes for any count); std::invalid_argument when negative.
void to_srgb8(const RgbFloatImage& in, const PixelRect& rect, float exposure, Rgb8Image& out,
              ToneMap op = ToneMap::clamp, int threads = 1);

}  // namespace mogao
