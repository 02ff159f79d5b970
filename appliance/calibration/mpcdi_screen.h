// SPDX-License-Identifier: Apache-2.0
// Conversions between MPCDI files and the appliance's ScreenCalibration (2d profile only).
//
// MPCDI 2d profile -> ScreenCalibration (to_screen_calibration):
//   * content frame = the buffer (Xresolution x Yresolution); one projector per region, in file
//     order, id = region id, output = region resolution.
//   * warp: PFM channels r, g are normalised 2D positions; by default relative to the REGION
//     (content u = x + xsize * r, v = y + ysize * g), which is how the custom Media2D fixture lays
//     two projectors side by side with identical-looking warps; WarpSpace::buffer reads r, g as
//     buffer coordinates directly. Channel b is ignored (0 in every 2d file). NaN in r or g = no
//     content (both NaN).
//   * blend: alpha value a of an n-bit map, max = 2^n - 1: weight = (a / max)^gammaEmbedded
//     (MPCDI alpha maps store gamma-encoded attenuation). gammaEmbedded 0 (not recorded, as in
//     SampleMPCDI) uses options.assumed_gamma (2.2, the reference examples' value). RGB alpha maps
//     become the mean of the three channel weights (BlendMask has one weight; per-channel blending
//     is lost, with a note).
//   * response: MPCDI v1.0 does not carry the projector's response: the region's ResponseLUT
//     extension entry when present (MpcdiResponseLut in mpcdi_types.h), else options.response
//     (gamma 2.2).
//   * beta (black-level offset, BlackOffset in projector_calibration.h): code / (2^bitDepth - 1)
//     is the offset in linear light in content units, no gamma (black offsets are small; a gamma
//     would spend the codes where they are not needed); gray maps apply to r, g and b. MPCDI v1.0
//     names the beta map the black-level offset map but leaves its encoding to the profile; this
//     is the encoding mogao writes and reads (docs/calibration.md, "Black level").
//   * distortion maps have no place in ScreenCalibration and are ignored, with a note when they
//     hold non-zero data.
// ScreenCalibration -> MPCDI 2d profile (to_mpcdi): the inverse with region = bounding box of the
// projector's finite warp positions (clamped to [0, 1], rounded to 6 significant digits as "%g"
// prints them), warp relative to it, alpha gray at the
// chosen bit depth and gamma, beta as a 16-bit RGB map when the projector has one, the response as
// the ResponseLUT extension entry when options.write_response, level 3 for per-pixel warps (warp
// grid larger than a tenth of the region, the reference library's rule) and 1 for coarse ones.
#pragma once

#include <string>
#include <vector>

#include "appliance/calibration/mpcdi_types.h"
#include "appliance/warp/response_curve.h"
#include "common/projector_calibration.h"

namespace mogao {

enum class WarpSpace { region, buffer };

struct ScreenConversionOptions {
    std::size_t buffer = 0;  // which <buffer> is the content frame
    WarpSpace warp_space = WarpSpace::region;
    double assumed_gamma = 2.2;                      // for gammaEmbedded 0, (0, 10]
    ResponseCurve response = make_gamma_response();  // every projector's response
};

// Throws MpcdiError (profile not 2d, buffer index, warp with fewer than 2 channels, grids larger
// than the region resolution, invalid result) naming the region and field.
[[nodiscard]] ScreenCalibration to_screen_calibration(const MpcdiFile& file,
                                                      const ScreenConversionOptions& options = {},
                                                      std::vector<std::string>* notes = nullptr);

struct MpcdiExportOptions {
    int alpha_bit_depth = 8;   // 8 (what the reference library reads) or 16 (finer blends)
    double alpha_gamma = 2.2;  // gammaEmbedded written and applied, (0, 10]
    std::string buffer_id = "buffer1";
    std::string date;             // empty = the time of writing
    bool write_response = false;  // write each projector's response LUT (mogao extension entry)
};

// Throws std::invalid_argument for an invalid screen (validate_screen) or options.
[[nodiscard]] MpcdiFile to_mpcdi(const ScreenCalibration& screen, const MpcdiExportOptions& options = {});

// The largest blend-weight error the alpha quantisation of to_mpcdi can introduce:
// half a code step through the gamma, max over [0, 1] of d/da (a^gamma) * 0.5 / (2^bits - 1).
[[nodiscard]] double alpha_quantisation_bound(int bit_depth, double gamma);

}  // namespace mogao
