// SPDX-License-Identifier: Apache-2.0
// Reading an MPCDI v1.0 file (see mpcdi_types.h for what comes back, docs/calibration.md for the
// conventions and the quirks of the reference-library files it accepts).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "appliance/calibration/mpcdi_types.h"

namespace mogao {

// Reads the ZIP, mpcdi.xml (or "mpacs.xml", a name other v1 implementations used, as the
// reference reader also accepts) and every map it references: PFM warps and distortion maps (PF or
// Pf, either byte order), PNG alpha and beta maps (gray or RGB, 8 or 16 bits) which must match the
// componentDepth/bitDepth declared in the XML.
//
// Throws MpcdiError whose message starts with "read_mpcdi '<path>'" and names the entry
// ("entry 'AlphaMap-proj1.png'") or the XML element and field, with the limit or reason: not a
// file, not a ZIP, no mpcdi.xml, unsafe entry names (path traversal), malformed XML, missing or
// out-of-range attributes, missing or corrupt entries, PFM/PNG size or format mismatches,
// infinite PFM samples. Never returns a partial file.
//
// Accepted quirks are described, one line each, in `notes` when not null: the originof3DData
// writer bug, gammaEmbedded 0, archive entries no region references.
[[nodiscard]] MpcdiFile read_mpcdi(const std::filesystem::path& path, std::vector<std::string>* notes = nullptr);

}  // namespace mogao
