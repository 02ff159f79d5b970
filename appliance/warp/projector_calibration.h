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
// for a 1920x1080 projector) are sampled "corner-aligned on pixel centres": grid sample (i, j) of a
// Gw x Gh grid sits on output pixel centre (i * (W - 1) / (Gw - 1), j * (H - 1) / (Gh - 1)) of a
// W x H output (0 when Gw or W is 1), so sample (0, 0) is the top-left pixel, sample
// (Gw-1, Gh-1) the bottom-right pixel, and a per-pixel grid (Gw = W) is used as is. Between
// samples the value is bilinear. In GL terms: texture coordinate
// s = (x * (Gw - 1) / (W - 1) + 0.5) / Gw for output pixel x, GL_LINEAR, CLAMP_TO_EDGE.
// The CPU definition is sample_warp()/sample_blend() in appliance/warp/warp_sampling.h; the
// checks (sizes, finiteness, ranges) are in appliance/warp/calibration_validation.h.
#pragma once

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "renderfarm/view/pixel_rect.h"

namespace mogao {

// Per output pixel: where in the content frame it samples. NaN (both u and v) = no content there
// (outside the screen): the output shows black.
struct WarpMap {
    ImageSize size;                 // grid samples: the output size, or coarser (see sample_warp)
    std::vector<float> uv;          // size.width * size.height * 2, row-major, (u, v) interleaved
};

// Per output pixel: attenuation in linear light in [0, 1] (1 = full brightness) applied before the
// response curve, so overlaps sum to 1 on the screen.
struct BlendMask {
    ImageSize size;                 // grid samples: the output size, or coarser (see sample_blend)
    std::vector<float> weight;      // size.width * size.height
};

// The projector's response: display value = lut(linear value). Stored as a per-channel table of
// `entries` samples of the inverse response over linear [0, 1] (the default is the sRGB-like
// gamma 2.2 encoding, x^(1/2.2)). Sample k sits at linear k / (entries - 1); between samples the
// table is linear (apply_response/invert_response in appliance/warp/response_curve.h).
struct ResponseCurve {
    std::array<std::vector<float>, 3> lut;  // each of the same length >= 2, values in [0, 1]
};

struct ProjectorCalibration {
    std::string id;                 // region id (MPCDI) e.g. "proj0"
    ImageSize output;               // projector resolution in pixels
    WarpMap warp;
    BlendMask blend;
    ResponseCurve response;
};

struct ScreenCalibration {
    ImageSize content;              // content frame size the warps were made for
    std::vector<ProjectorCalibration> projectors;
};

}  // namespace mogao
