// SPDX-License-Identifier: Apache-2.0
// The printable image of one tag, generated from the family's code table (the bits of
// apriltag_family_t::codes laid out at bit_x/bit_y), never shipped as a binary.
//
// One value per cell, 0 = black, 255 = white, row-major, top row first, as the tag is printed and
// seen from the front. The bitmap is total_width_cells square. For the classic families
// (tag36h11: 10 cells) the outer ring is white, the next ring black and the data bits are inside;
// the detector's four corners are the outer corners of the black ring, a square of
// border_width_cells (8 for tag36h11) centred in the bitmap. "Tag size" everywhere in mogao is the
// side of that square in metres, as in AprilTag's own pose code.
//
// Layout rule: AprilTag 3 apriltag_to_image() (apriltag.c): bit i (most significant first) of the
// code is cell (bit_x[i] + b, bit_y[i] + b) with b = (total_width - width_at_border) / 2.
#pragma once

#include <cstdint>
#include <vector>

#include "appliance/tracker/tag_family.h"

namespace mogao {

struct TagBitmap {
    int cells = 0;                     // side, in cells
    int border_cells = 0;              // side of the corner square, in cells
    std::vector<std::uint8_t> pixels;  // cells * cells values
    [[nodiscard]] std::uint8_t at(int x, int y) const {
        return pixels[static_cast<std::size_t>(y) * static_cast<std::size_t>(cells) + static_cast<std::size_t>(x)];
    }
};

// Throws std::invalid_argument if id is outside [0, family.code_count()).
[[nodiscard]] TagBitmap make_tag_bitmap(const TagFamily& family, int id);

}  // namespace mogao
