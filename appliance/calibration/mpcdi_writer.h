// SPDX-License-Identifier: Apache-2.0
// Writing an MPCDI v1.0 file in the reference library's conventions (ZIP entry names and order,
// PFM "-1.000000" little-endian bottom-to-top, "Xresolution", "%g" numbers, DOS date 0) without
// its bugs: <originof3DData> holds the real origin (spelling: see mpcdi_xml.h) and
// <gammaEmbedded> the real gamma.
#pragma once

#include <filesystem>

#include "appliance/calibration/mpcdi_types.h"

namespace mogao {

// Entry names default to "GeometryWarpFile-<id>.pfm", "AlphaMap-<id>.png", "BetaMap-<id>.png",
// "DistortionMapFile-<id>.pfm" where a map's path is empty; entries are ordered by region id
// (byte-wise, like the reference's std::map), per region warp, alpha, beta, distortion, then
// mpcdi.xml last.
//
// Atomic: the archive is written to a temporary file in the destination's folder, flushed to disk
// (fsync), then renamed over `path`, so a crash or a full disk leaves the previous calibration
// intact and never a half-written one.
//
// Throws MpcdiError starting with "write_mpcdi '<path>'" naming the region/field at fault, for
// anything read_mpcdi would reject: level outside 1..4, version not 1.x, no buffer or region,
// resolutions outside 1..16384, region placement outside the buffer, non-finite frustum or
// coordinate-frame values, empty or duplicate ids and entry names, unsafe entry names,
// ids unusable in entry names ('/', '\\', control characters), inconsistent maps (size vs values,
// channels, bit depth, values over the bit depth, infinite PFM values), negative or non-finite
// gammaEmbedded, I/O failures (missing folder, disk full).
void write_mpcdi(const std::filesystem::path& path, const MpcdiFile& file);

}  // namespace mogao
