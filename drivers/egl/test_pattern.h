// SPDX-License-Identifier: Apache-2.0
// Calibrations and frames for bring-up and tests: an identity calibration (the output shows the
// content unchanged), standard response curves and a test pattern a technician can read (colour
// bars, a one-pixel grid, a white border and an arrow-free corner marker in the top-left).
#pragma once

#include <cstddef>
#include <string>

#include "common/image.h"
#include "common/projector_calibration.h"

namespace mogao {

// Response LUT of `entries` samples of the sRGB encoding (IEC 61966-2-1) over linear [0, 1]: with
// it, the output's 8-bit codes equal the sRGB content's codes (the end-to-end identity). 4096
// entries keep the piecewise-linear error below 0.01 of a code.
[[nodiscard]] ResponseCurve srgb_response(std::size_t entries = 4096);

// Response LUT x^(1/gamma) per channel (gamma > 0), `entries` >= 2 samples.
[[nodiscard]] ResponseCurve gamma_response(double gamma, std::size_t entries = 1024);

// Output `output` shows a `content`-sized frame stretched over it: warp maps output pixel centre
// (x + 0.5, y + 0.5) to content (u, v) = ((x + 0.5) / W, (y + 0.5) / H) at full output resolution,
// blend 1 (a 1x1 mask), sRGB response. With content == output the output equals the content.
[[nodiscard]] ProjectorCalibration identity_calibration(std::string id, ImageSize output);

// sRGB test pattern: 8 colour bars (white, yellow, cyan, green, magenta, red, blue, black) in the
// top half, a grey ramp below, a 1-pixel white grid every 64 pixels and a white 1-pixel border;
// the top-left 16x16 block is red so the orientation is obvious on a wall.
[[nodiscard]] Rgb8Image make_test_pattern(ImageSize size);

}  // namespace mogao
