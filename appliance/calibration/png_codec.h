// SPDX-License-Identifier: Apache-2.0
// PNG alpha and beta maps of MPCDI, through libpng's classic API so that sample values pass
// through untouched (the simplified png_image API would colour-manage them by any gAMA/sRGB chunk).
//
// Read: 8- or 16-bit gray (colour type 0) or RGB (colour type 2), interlaced or not; other colour
// types (palette, with alpha) and bit depths are rejected with MpcdiError naming the entry, since
// MPCDI alpha/beta maps are 1 or 3 components. Ancillary chunks (gAMA, sRGB, iCCP) are ignored:
// the map's gamma is mpcdi.xml's gammaEmbedded.
// Write: exactly IHDR, IDAT, IEND (like the reference writer), non-interlaced, zlib default level.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "appliance/calibration/mpcdi_types.h"

namespace mogao {

// Throws MpcdiError prefixed `who` for corrupt data, unsupported types or sizes over 16384.
[[nodiscard]] PngMap decode_png_map(std::span<const std::uint8_t> bytes, const std::string& who);

// Throws MpcdiError prefixed `who` for an inconsistent map (channels 1/3, bit depth 8/16, size,
// values over the bit depth).
[[nodiscard]] std::vector<std::uint8_t> encode_png_map(const PngMap& map, const std::string& who);

}  // namespace mogao
