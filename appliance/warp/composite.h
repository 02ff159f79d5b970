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

// Content light `linear` at content point (u, v) less the indirect light field there (render_output's
// linear'_c below: sample_content of the field, clamped at 0); `linear` unchanged when the field is empty.
[[nodiscard]] std::array<float, 3> take_off_indirect_light(std::array<float, 3> linear, const RgbFloatImage& indirect,
                                                           double u, double v);

// The projector's input signal, per output pixel (x, y) and channel c:
//
//   uv         = sample_warp(x, y)                  the content point the pixel lands on
//   linear_c   = sample_content(content_linear, uv)
//   linear'_c  = max(linear_c - sample_content(indirect, uv)_c, 0)     (linear_c when indirect is empty)
//   out_c      = lut_c(clamp(linear'_c * sample_blend(x, y) + sample_beta(x, y)_c, 0, 1))
//
// `indirect` is the screen's own light (interreflection of a concave screen) that the content
// would otherwise get on top of itself, taken off before the blend (Bimber et al., "Compensating
// indirect scattering for immersive and semi-immersive projection displays", IEEE VR 2006): a
// content-space RGB field of any size (e.g. one texel per 0.1 m screen patch), linear light in
// content units (1 = the light content 1.0 makes), read like the content (bilinear at texel
// centres (i + 0.5) / W, clamp to edge; 1x1 is a constant). Where it exceeds the content the
// pixel shows beta alone. Empty (0 x 0, no values; the default) subtracts nothing: the result is
// bit for bit the one without it. Pixels with no content (NaN warp) are signal 0 (black). Returns
// an image of projector.output size. Throws std::invalid_argument for an invalid projector
// (validate_projector) or content image, and for an indirect field whose size does not match its
// values or that holds a non-finite or negative value.
[[nodiscard]] RgbFloatImage render_output(const ProjectorCalibration& projector, const RgbFloatImage& content_linear,
                                          const RgbFloatImage& indirect = {});

// The light on the screen, content-sized: for every content pixel, the sum over projectors of
// response^-1(signal) (invert_response) bilinearly sampled at the output position that lands on
// the pixel (build_inverse_warp: cell-scan inverse of the bilinear warp). Content pixels that no
// projector reaches are black. outputs[k] must be screen.projectors[k].output sized.
// Throws std::invalid_argument for an invalid screen (validate_screen) or mismatched outputs.
[[nodiscard]] RgbFloatImage composite_on_screen(const ScreenCalibration& screen,
                                                const std::vector<RgbFloatImage>& outputs);

}  // namespace mogao
