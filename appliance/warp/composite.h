// SPDX-License-Identifier: Apache-2.0
// CPU reference of what the projectors put on the screen, in both directions. Slow and exact by
// construction: the GL backend's output is checked against render_output, and the calibration
// itself against composite_on_screen (a calibration is right when the composite equals the
// content).
//
// Colour: images are RgbFloatImage (common/image.h). Content and screen light are linear,
// display-referred in [0, 1] (1 = the projector's full white); projector outputs hold the
// projector's input signal in [0, 1] (after the response curve).
// Pixel centres: content pixel (i, j) is at normalised ((i + 0.5) / W, (j + 0.5) / H); output pixel
// (x, y) at (x + 0.5, y + 0.5) (projector_calibration.h).
//
// Screen model: a projector adds its linear light at the content point its pixel lands on; light
// adds linearly between projectors (so blend weights must sum to 1). The projectors' different
// pixel densities and brightness fall-off are outside the model (a real calibration measures them
// into the alpha/beta maps).
#pragma once

#include <array>
#include <vector>

#include "common/image.h"
#include "common/projector_calibration.h"

namespace mogao {

// Bilinear sample of `content` at normalised (u, v) with the pixel-centre convention above and
// clamp-to-edge: u = (i + 0.5) / W returns pixel i exactly. NaN u or v returns black.
// Precondition: content non-empty with width*height*3 values.
[[nodiscard]] std::array<float, 3> sample_content(const RgbFloatImage& content, double u, double v);

// The projector's input signal: per output pixel, warp (sample_warp) -> sample_content ->
// x blend weight (sample_blend) + black offset (sample_beta, per channel) -> clamp to [0, 1] ->
// response LUT per channel. Pixels with no
// content (NaN warp) are signal 0 (black). Returns an image of projector.output size.
// Throws std::invalid_argument for an invalid projector (validate_projector) or content image.
[[nodiscard]] RgbFloatImage render_output(const ProjectorCalibration& projector, const RgbFloatImage& content_linear);

// The light on the screen, content-sized: for every content pixel, the sum over projectors of
// response^-1(signal) (invert_response) bilinearly sampled at the output position that lands on
// the pixel (build_inverse_warp: cell-scan inverse of the bilinear warp). Content pixels that no
// projector reaches are black. outputs[k] must be screen.projectors[k].output sized.
// Throws std::invalid_argument for an invalid screen (validate_screen) or mismatched outputs.
[[nodiscard]] RgbFloatImage composite_on_screen(const ScreenCalibration& screen,
                                                const std::vector<RgbFloatImage>& outputs);

}  // namespace mogao
