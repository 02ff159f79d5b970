// SPDX-License-Identifier: Apache-2.0
// Thumbnails and contact sheets: one picture showing many frames (a turntable sweep, every rank's
// region, a benchmark's quality ladder) for reports and for eyeballing regressions.
#pragma once

#include <cstdint>
#include <span>

#include "common/image.h"

namespace mogao {

// Area-average (box filter) resampling: each output pixel is the mean of the source area it
// covers, partial source pixels weighted by the fraction covered. Exact integer arithmetic, rounded
// half up, so results are deterministic across compilers. Meant for downscaling (no aliasing, no
// ringing); upscaling degenerates to nearest neighbour. Throws std::invalid_argument for an empty
// target or malformed source.
[[nodiscard]] Rgb8Image downscale_box(const Rgb8Image& source, ImageSize target);

// Background and thumbnail layout of make_contact_sheet.
inline constexpr std::uint8_t kContactSheetBackground = 24;  // dark grey, R = G = B

// Grid of thumbnails, left to right then top to bottom, on a dark grey background.
// Each frame is box-downscaled to `thumb_width` wide keeping its aspect ratio (height rounded,
// at least 1). The grid has min(columns, frames.size()) columns; every cell is thumb_width wide and
// as tall as the tallest thumbnail, thumbnails are centred vertically in their cell, and there are
// `border_px` pixels of background around and between cells. Hence
//   width  = cols * thumb_width + (cols + 1) * border_px
//   height = rows * cell_height + (rows + 1) * border_px,  rows = ceil(frames / cols).
// Throws std::invalid_argument for no frames, columns < 1, thumb_width < 1, border_px < 0 or a
// malformed frame.
[[nodiscard]] Rgb8Image make_contact_sheet(std::span<const Rgb8Image> frames, int columns, int thumb_width,
                                           int border_px = 4);

}  // namespace mogao
