// SPDX-License-Identifier: Apache-2.0
// A 5x7 pixel bitmap font for the kiosk's own screens (the "connecting" card): upper-case A-Z
// (lower case is drawn upper case), digits, space and . : - / [ ] _ = ; any other character is drawn
// as '?'. Each glyph cell is 6x8 font pixels (one column and one row of spacing), scaled by an
// integer factor. Pixels: (0, 0) top-left of the image, rows top first (common/image.h).
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

#include "common/image.h"

namespace mogao {

inline constexpr int kGlyphWidth = 5;
inline constexpr int kGlyphHeight = 7;
inline constexpr int kGlyphAdvance = 6;     // glyph width + 1 column of spacing
inline constexpr int kGlyphLineHeight = 8;  // glyph height + 1 row of spacing

// Rows top first; bit 4 is the leftmost column.
[[nodiscard]] const std::array<std::uint8_t, kGlyphHeight>& glyph_rows(char c);

// Width in image pixels of `text` drawn at `scale` (no trailing spacing column); 0 for "".
[[nodiscard]] int text_width(std::string_view text, int scale);

// Draws `text` with its top-left corner at (x, y), each font pixel a scale x scale block of `rgb`.
// Pixels outside the image are clipped (never written). scale < 1 draws nothing.
void draw_text(Rgb8Image& image, int x, int y, int scale, std::string_view text, std::array<std::uint8_t, 3> rgb);

}  // namespace mogao
