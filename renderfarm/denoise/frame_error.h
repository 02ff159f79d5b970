// SPDX-License-Identifier: Apache-2.0
// Error of a frame against a converged reference, as the viewer sees it: both linear radiance
// frames go through the scene's display transform (exposure, tone map, sRGB8: renderfarm/trace/
// film.h) and are compared by PSNR over all R, G, B samples (common/image_compare.h, peak 255).
// Throws std::invalid_argument if the sizes differ (as psnr does).
#pragma once

#include "common/image.h"
#include "renderfarm/scene/scene.h"

namespace mogao {

[[nodiscard]] Rgb8Image display_frame(const RgbFloatImage& radiance, float exposure, ToneMap tone_map);

[[nodiscard]] double display_psnr(const RgbFloatImage& frame, const RgbFloatImage& reference, float exposure,
                                  ToneMap tone_map);

}  // namespace mogao
