// SPDX-License-Identifier: Apache-2.0
// mpcdi.xml of an MPCDI v1.0 file: parse into MpcdiFile (maps not loaded yet) and print.
//
// Element and attribute names are the reference library's (src/IO/mpcdiXMLStrings.h): buffer and
// region resolutions are spelled "Xresolution"/"Yresolution" (MPCDI v2 writers use "xResolution";
// v2 is not supported and is rejected by its version attribute).
//
// originOf3DData: the reference library names the element "originof3DData" (lower-case "of") and
// its writer always repeats the <interpolation> text in it. The parser accepts both spellings; a
// value that is not an origin but equals the interpolation text is that writer bug and reads as
// "unknown" (with a note). The printer writes the real origin value under the reference spelling
// "originof3DData", because the reference reader requires exactly that element and fails the
// whole file without it; the spelling is the only concession, the value is no longer a copy.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "appliance/calibration/mpcdi_types.h"

namespace mogao {

// Parses the document; every region gets its fileset's paths, warp attributes and alpha gamma.
// Map sizes are empty, PngMap channels/bit_depth hold the declared componentDepth/bitDepth (the
// reader checks the PNG against them). Throws MpcdiError prefixed `who` naming the element (with
// its id) and the attribute or child at fault. Observed quirks that were accepted are appended to
// `notes` when it is not null.
[[nodiscard]] MpcdiFile parse_mpcdi_xml(std::string_view text, const std::string& who, std::vector<std::string>* notes);

// The document in the fixtures' layout: XML declaration, 4-space indent, LF line ends, attribute
// and element order as the reference writer, numbers via format_number ("%g" when exact).
// Region and fileset order follow file.buffers. An empty date prints the current UTC time.
[[nodiscard]] std::string print_mpcdi_xml(const MpcdiFile& file);

}  // namespace mogao
