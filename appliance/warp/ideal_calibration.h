// SPDX-License-Identifier: Apache-2.0
// The ideal calibration: N identical projectors side by side on the cylindrical screen, each
// covering one vertical band of the content frame with a chosen overlap to its neighbours.
//
// Assumption (why the warp is linear): the content frame is already the cylinder's unrolled
// surface (CylinderScreen in common/view_request.h maps content column u linearly to the
// angle on the arc and row v linearly to the height). A projector whose optical axis meets the
// cylinder axis and whose image is a rectangle on the unrolled surface therefore needs a linear
// map from its pixels to content (u, v); a real projector on a curved screen needs the curved map
// a camera-based calibration measures (MPCDI). The ideal calibration also ignores aspect ratio:
// each projector's full image is stretched onto its band.
//
// Layout, normalised content u: band width b = 1 / (N - (N - 1) * overlap), projector k covers
// [u0_k, u1_k] = [k * b * (1 - overlap), u0_k + b], full height v in [0, 1]; neighbours share
// overlap * b (with overlap 0 the shared edge belongs to the right-hand projector). Output pixel
// (x, y) of a W x H projector samples u = u0_k + b * (x + 0.5) / W, v = (y + 0.5) / H (its pixel
// footprint tiles the band exactly).
//
// Blend (in linear light, before the response): outside overlaps 1; in the overlap [a, c] of
// projectors k and k + 1, t = (u - a) / (c - a), projector k + 1 gets S(t) and projector k gets
// 1 - S(t) with S the smoothstep 3t^2 - 2t^3 (the cubic Hermite ramp of GLSL smoothstep(); C1, so
// no visible kink at the overlap edges). The two weights sum to 1 at every content point up to
// rounding (2.3e-16 in double; the float32 masks round each weight by at most 6e-8).
// Response: gamma 2.2 LUT (make_gamma_response).
#pragma once

#include <vector>

#include "appliance/warp/response_curve.h"
#include "common/projector_calibration.h"

namespace mogao {

struct IdealCalibrationParams {
    int projectors = 3;             // N in [1, 64]
    double overlap = 0.15;          // fraction of one projector's band shared with a neighbour, [0, 0.5)
    ImageSize output{1024, 768};    // each projector's resolution, 1..16384 per side
    ImageSize content{1920, 1080};  // content frame the warps address, 1..16384 per side
    double gamma = 2.2;             // response gamma, (0, 10]
    int response_entries = kDefaultResponseEntries;
};

// One projector's band of normalised content u.
struct ContentBand {
    double u0 = 0.0;
    double u1 = 1.0;
};

// The N bands of the layout above. Throws std::invalid_argument for N or overlap out of range.
[[nodiscard]] std::vector<ContentBand> ideal_bands(int projectors, double overlap);

// Smoothstep 3t^2 - 2t^3 with t clamped to [0, 1].
[[nodiscard]] double smooth_ramp(double t);

// Blend weight of projector k at content u (0 outside its band). Sums to 1 over k for every
// u in [0, 1]. Throws std::invalid_argument when k is not an index of bands.
[[nodiscard]] double ideal_blend_weight(const std::vector<ContentBand>& bands, int k, double u);

// The full calibration: ids "proj0".."proj{N-1}", per-pixel warp and blend (grid = output size).
// Throws std::invalid_argument naming the parameter and its limit.
[[nodiscard]] ScreenCalibration make_ideal_calibration(const IdealCalibrationParams& params);

}  // namespace mogao
