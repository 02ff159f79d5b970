// SPDX-License-Identifier: Apache-2.0
// Seams as the viewer sees them, against the virtual rig's ground truth (never the calibration's
// own prediction): flat grey content through a ScreenCalibration (warp validity, blend, beta,
// response, as render_output computes them) onto the rig's true light paths and responses
// (virtual_rig.h: F(x, y) brightness_c (black + (1 - black) s^gamma_c) per projector, F the lens fall-off,
// times the screen's gain toward the rig's viewer (VirtualRig::viewer_m), plus one bounce of the screen's own
// light and the ambient).
//
// Colour: the rig's linear RGB light is read as ITU-R BT.709 / sRGB primaries with D65 white
// (IEC 61966-2-1 matrix to CIE XYZ), luminance Y = 0.2126 R + 0.7152 G + 0.0722 B; CIELAB (CIE
// 15:2004) relative to the screen's own white (the median XYZ of full-white content, to which a
// viewer adapts); colour difference CIE76 Delta E*ab = Euclidean distance in L*a*b* (CIE 1976; a
// Delta E near 1 is about a just-noticeable difference, Sharma, Digital Color Imaging Handbook 2003).
#pragma once

#include <array>
#include <vector>

#include "appliance/autocal/indirect_light.h"
#include "appliance/autocal/rig_bridge.h"
#include "appliance/rig/virtual_rig.h"
#include "common/projector_calibration.h"

namespace mogao::autocal {

struct SeamColour {
    double level = 0.0;                     // content value (linear, all channels)
    int samples = 0;                        // content points of the default grid (the figures over all points)
    int seam_samples = 0;                   // points of the seam grid lit by two or more projectors (blend > 0)
    double reference_luminance = 0.0;       // median Y over points lit by one projector
    double luminance_max_deviation = 0.0;   // max |Y / reference - 1| over all points
    double seam_luminance_deviation = 0.0;  // the same over the seam points
    // The same with each seam point's light averaged over the footprint of the output pixel that shows it (the
    // projector with the largest blend weight there): what a viewer who does not resolve a projector's pixel
    // sees. A point alone can sit on another projector's black edge inside that pixel, a step of that
    // projector's black that no calibration removes (one pixel's light is uniform; the black is emitted
    // whatever the signal): |Y / reference - 1| there is at least half of it on one side of the edge.
    double seam_luminance_pixel_max = 0.0;
    double delta_e_max = 0.0;         // max CIE76 Delta E from the reference colour, all points
    double seam_delta_e = 0.0;        // the same over the seam points
    double seam_luminance_p95 = 0.0;  // 95th percentile of the seam points' |Y / reference - 1|
    double luminance_p95 = 0.0;       // the same over all points (a smooth field over the screen shows here)
    double seam_delta_e_p95 = 0.0;    // 95th percentile of the seam points' Delta E
};

// Points: a grid of `grid` content points (401 x 101 by default; pixel_dense_seam_grid for a maximum that sees
// lines one projector pixel wide) inset by `inset` of the frame on each side. The reference colour is the
// per-channel median over the default grid's points lit by one projector. A seam point's pixel mean is taken
// over 8 x 8 points of the pixel's footprint, placed on the screen by the rig's true projector: for every seam
// point on the default grid, and on a denser one for the 4096 seam points of largest deviation (a pixel's mean is
// at most the largest deviation inside it, and such a grid has a point in or next to every pixel). Throws
// std::invalid_argument for a grid under 2 x 2.
// With `indirect`, the content is shown less the indirect light's field for flat content at `level`
// (indirect_light.h; render_output's `indirect`), as the outputs show it.
// `defocused`: each defocused projector's (RigProjector::blur_px > 0) light at a point is its pixels' spread by their
// aperture and the blur (projector_footprint.h), as the screen shows it; else each pixel's light is a sharp step.
[[nodiscard]] SeamColour measure_seam_colour(const rig::VirtualRig& rig, const ScreenCalibration& calibration,
                                             double level, double inset = 0.01, const IndirectLight* indirect = nullptr,
                                             bool defocused = false, SeamGridSize grid = {});

// Linear RGB (BT.709 primaries) -> CIELAB against white `white_xyz`.
[[nodiscard]] std::array<double, 3> rgb_to_lab(const std::array<double, 3>& rgb,
                                               const std::array<double, 3>& white_xyz);
[[nodiscard]] std::array<double, 3> rgb_to_xyz(const std::array<double, 3>& rgb);

}  // namespace mogao::autocal
