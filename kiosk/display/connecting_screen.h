// SPDX-License-Identifier: Apache-2.0
// The "connecting" card the kiosk shows from start-up until the first good frame from the farm:
// never a black screen, so staff can tell "the appliance is up and waiting for the farm" from
// "projector off / no signal" at a glance. It is an ordinary content frame (sRGB RGB8, rows top
// first) and goes through the same warp and blend as the farm's frames, so its grid also shows
// the projectors' geometry and overlaps while nothing else is on screen.
//
// Look: a dim blue-grey vertical gradient (sRGB codes about 20-60), a grid of lighter lines every
// 1/24 of the width, a mid-grey frame around the edge, "CONNECTING" in large letters across the
// middle and `detail` (e.g. the farm's endpoint) in smaller letters below, both light grey
// (codes 150-220). Sizes from 1x1 upward are valid; text that does not fit is scaled down or
// clipped.
#pragma once

#include <string_view>

#include "common/image.h"

namespace mogao {

// Throws std::invalid_argument for a size outside [1, 16384] per side.
[[nodiscard]] Rgb8Image make_connecting_screen(ImageSize content, std::string_view detail);

// The same card with another title (the service card, kiosk/display/service_screen.h).
[[nodiscard]] Rgb8Image make_title_card(ImageSize content, std::string_view title, std::string_view detail);

}  // namespace mogao
