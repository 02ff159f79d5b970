// SPDX-License-Identifier: Apache-2.0
// PFM (Portable Float Map, the Netpbm-family float format of Paul Debevec's HDRShop, used by MPCDI
// for geometry warp and distortion maps).
//
// File layout: "PF" (3 channels) or "Pf" (1 channel), whitespace, width, whitespace, height,
// whitespace, scale, exactly one whitespace byte, then width*height*channels float32 samples,
// rows stored BOTTOM row first. The sign of the scale gives the byte order (negative = little
// endian); its magnitude has no meaning for MPCDI and is ignored (the reference reader ignores it
// too). PfmMap holds rows top row first (mpcdi_types.h).
//
// Decisions: NaN samples are kept (some writers mark "no data" with NaN; to_screen_calibration
// turns them into "no content"); +-Inf is rejected, because no MPCDI quantity is infinite and an
// Inf would poison every interpolation around it. Trailing bytes after the samples are rejected as
// a size mismatch, like a short file.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "appliance/calibration/mpcdi_types.h"

namespace mogao {

inline constexpr int kMaxMapDimension = 16384;

// Throws MpcdiError prefixed `who` (archive and entry) naming the header field, the sizes or the
// offending sample.
[[nodiscard]] PfmMap decode_pfm(std::span<const std::uint8_t> bytes, const std::string& who);

// The reference writer's exact bytes: "PF\n<W> <H>\n-1.000000\n" ("Pf" for 1 channel), little
// endian, rows bottom-to-top. Throws MpcdiError prefixed `who` for an inconsistent map.
[[nodiscard]] std::vector<std::uint8_t> encode_pfm(const PfmMap& map, const std::string& who);

}  // namespace mogao
