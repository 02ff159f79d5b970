// SPDX-License-Identifier: Apache-2.0
// Portable float map (PFM) of linear RGB, the exchange format between our renders and Blender's
// (bench/peer/cycles_scene.py writes the same layout).
//
// Layout (Paul Debevec's PFM as read by netpbm/OpenCV): "PF\n<W> <H>\n-1.0\n" then W*H*3 little-endian
// float32, rows from the BOTTOM of the image up (the PFM convention); our RgbFloatImage rows run top
// down, so rows are flipped on read and write. A positive scale (big-endian) is refused.
// Errors: EINVAL naming the file for a malformed header or a short file, errno for I/O.
#pragma once

#include <filesystem>

#include "common/image.h"
#include "common/result.h"

namespace mogao::peer {

[[nodiscard]] Status write_pfm(const std::filesystem::path& file, const RgbFloatImage& image);
[[nodiscard]] Result<RgbFloatImage> read_pfm(const std::filesystem::path& file);

}  // namespace mogao::peer
