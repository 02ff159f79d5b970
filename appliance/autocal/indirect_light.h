// SPDX-License-Identifier: Apache-2.0
// The light a concave screen throws onto itself, predicted for each frame and taken out of the content before it is
// shown (Bimber, Grundhoefer, Zeidler, Danch & Kapakos, "Compensating indirect scattering for immersive and
// semi-immersive projection displays", IEEE VR 2006). The colour step flattens each projector's direct light; the
// screen's own light comes on top of it and depends on what is shown (a bright wall lights the opposite one), so no
// fixed map can take it out. Pure maths, no GL: the outputs subtract the field it returns (render_output's
// `indirect`, ProjectorRenderer::set_indirect_light).
//
// Model (screen_bounce.h): the screen cut into patches about `patch_m` square in (theta, h); the calibrated outputs
// show content c (linear, per channel) as light K c toward the viewer (K the calibration's white, the same
// everywhere), which leaves patch j matte as K c_j / G_j, with G_j the screen's gain toward the viewer there (the
// blend-weighted harmonic mean over the projectors that light j, 1 on a matte screen); patch i then receives
// rho sum_j F_ij K c_j / G_j, seen matte. In content units (divided by K) the indirect light is
//   I_i = rho sum_j F_ij c_j / G_j.
// To show c, the outputs show c' = max(c - (I[c'] - I0), 0): the content less its own indirect light, two Jacobi
// steps from c' = c (rho F is a contraction: its largest row sum is well under 1 on any real screen). I0 is the
// least I[c'] over the patches that show content, so flat content stays as bright as the screen allows where the
// indirect light is least, and comes out flat (K (c + I0) everywhere) instead of brighter where the screen faces
// more of itself. Where the content is darker than its indirect light (a dark wall beside a bright one) c' clamps
// at 0 and the rest of the indirect light stays: no projector can show less than nothing.
//
// The field: an RgbFloatImage of columns() x rows() texels, one per patch, row 0 at the top of the screen and
// column 0 at its left end, so texel (i, j) sits at content ((i + 0.5) / columns, (j + 0.5) / rows) (the content's
// pixel-centre convention: content u = (theta + arc / 2) / arc, v = (top - h) / (top - bottom), autocal.h), read
// bilinearly with clamp to the edge (sample_content in appliance/warp/composite.h).
#pragma once

#include <vector>

#include "appliance/autocal/autocal.h"
#include "appliance/autocal/screen_bounce.h"
#include "common/image.h"
#include "common/projector_calibration.h"

namespace mogao::autocal {

class IndirectLight {
public:
    // `screen.interreflection` is rho (below kMinReflectance: none, field() returns an empty image); `projectors` the
    // fitted models and `calibration` the blend masks of the same projectors in the same order (for G_j).
    // Throws std::invalid_argument naming the field: rho outside [0, 1), a projector count that differs, or a
    // screen ScreenBounce refuses.
    IndirectLight(const ScreenModel& screen, const std::vector<DeviceModel>& projectors,
                  const ScreenCalibration& calibration, double patch_m = 0.1);

    // Below this reflectance the field stays under a tenth of a code of 8-bit white on any screen the colour step
    // measures (a matte screen measures 0.001 to 0.004), so none is computed.
    static constexpr double kMinReflectance = 0.01;
    [[nodiscard]] bool active() const { return rho_ >= kMinReflectance; }
    [[nodiscard]] int columns() const { return bounce_.columns(); }
    [[nodiscard]] int rows() const { return bounce_.rows(); }

    // The field to subtract (above) for content whose patch means (linear, content units, columns() x rows(),
    // row 0 at the top) are `patches`. Empty when !active(). Throws std::invalid_argument for another size.
    [[nodiscard]] RgbFloatImage field(const RgbFloatImage& patches) const;
    // The field for flat content `level` (all channels).
    [[nodiscard]] RgbFloatImage flat_field(double level) const;

    // Patch means of a linear content image of any size (nearest texel at `samples` x `samples` points of each
    // patch's content rectangle).
    [[nodiscard]] RgbFloatImage patch_means(const RgbFloatImage& content_linear, int samples = 4) const;

private:
    // I[c] for patch means c (content units, one plane per channel), patch index r * columns + c with r = 0 at the
    // bottom; written into `out` (same shape).
    void indirect(const std::array<std::vector<float>, 3>& c, std::array<std::vector<float>, 3>& out) const;

    ScreenBounce bounce_;
    double rho_ = 0.0;
    std::vector<double> inverse_gain_;  // 1 / G_j per patch (bottom row first); 0 where no projector lights j
    // rho F_ij / G_j, column j at [j * patches()], in float: the per-frame product reads it twice, and in float it
    // is half the memory traffic (a field under 0.1 summed over about a thousand terms keeps 1e-6 of a code).
    std::vector<float> transfer_;
};

}  // namespace mogao::autocal
