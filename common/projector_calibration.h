// SPDX-License-Identifier: Apache-2.0
// What one projector output needs to show its part of the cylindrical screen: a warp map, a blend
// mask and a per-channel response curve. Value types shared by the calibration reader/writer
// (MPCDI), the CPU reference compositor and the GL output backends (drivers/).
//
// Pixel convention: output pixel (x, y) has its centre at (x + 0.5, y + 0.5), (0, 0) top-left, rows
// top to bottom. Content coordinates (u, v) are normalised over the content frame (the farm's
// cylindrical-screen frame): u = 0 left edge, 1 right edge; v = 0 top edge, 1 bottom edge; a
// content pixel (i, j) of a W x H frame is centred at ((i + 0.5) / W, (j + 0.5) / H).
//
// Warp and blend grids coarser than the output (MPCDI levels 1 and 2 store e.g. 192x108 samples
// for a 1920x1080 projector) are sampled like a GL texture: an M-sample grid covers the whole
// W-pixel output, grid sample k is centred at output image position (k + 0.5) * W / M, and output
// pixel centre p = x + 0.5 reads grid position g = p * M / W - 0.5 (sample k at g = k), bilinear
// between samples, clamped to the edge samples. With M = W this is exactly one sample per pixel.
// In GL terms: texture coordinate (x + 0.5) / W with GL_LINEAR and CLAMP_TO_EDGE (drivers/egl
// does the same bilinear with texelFetch, docs/outputs.md). The CPU definition is
// sample_warp()/sample_blend() in appliance/warp/warp_sampling.h; the checks (sizes, finiteness,
// ranges) are in appliance/warp/calibration_validation.h.
#pragma once

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "common/pixel_rect.h"

namespace mogao {

// Per output pixel: where in the content frame it samples. NaN (both u and v) = no content there
// (outside the screen): the output shows black.
struct WarpMap {
    ImageSize size;         // grid samples: the output size, or coarser (see sample_warp)
    std::vector<float> uv;  // size.width * size.height * 2, row-major, (u, v) interleaved
};

// Per output pixel: attenuation in linear light in [0, 1] (1 = full brightness) applied before the
// response curve, so overlaps sum to 1 on the screen.
struct BlendMask {
    ImageSize size;             // grid samples: the output size, or coarser (see sample_blend)
    std::vector<float> weight;  // size.width * size.height
};

// The projector's response: display value = lut(linear value). Stored as a per-channel table of
// `entries` samples of the inverse response over linear [0, 1] (the default is the sRGB-like
// gamma 2.2 encoding, x^(1/2.2)). Sample k sits at linear k / (entries - 1); between samples the
// table is linear (apply_response/invert_response in appliance/warp/response_curve.h).
struct ResponseCurve {
    std::array<std::vector<float>, 3> lut;  // each of the same length >= 2, values in [0, 1]
};

// Per output pixel and channel: black-level offset (MPCDI beta map) in linear light, in the same
// units as the content (1 = the matched full white), added after the blend weight and before the
// response curve, so that the screen's black is as bright everywhere as in the brightest overlap
// (Majumder & Stevens, "Color nonuniformity in projection-based displays", IEEE TVCG 10(2), 2004).
// Empty (size 0 x 0) = no offset. Sampled like the blend mask (sample_beta in warp_sampling.h).
struct BlackOffset {
    ImageSize size;          // grid samples: the output size, or coarser; 0 x 0 = none
    std::vector<float> rgb;  // size.width * size.height * 3, row-major, r g b interleaved
};

// Per channel c of one output pixel (appliance/warp/composite.h, render_output):
//   linear_c = clamp(content_c * blend + beta_c, 0, 1); signal_c = response.lut[c](linear_c).
struct ProjectorCalibration {
    std::string id;    // region id (MPCDI) e.g. "proj0"
    ImageSize output;  // projector resolution in pixels
    WarpMap warp;
    BlendMask blend;
    ResponseCurve response;
    BlackOffset beta;  // optional (empty = none)
};

struct ScreenCalibration {
    ImageSize content;  // content frame size the warps were made for
    std::vector<ProjectorCalibration> projectors;
};

}  // namespace mogao
