// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/denoise/frame_error.h"

#include "common/image_compare.h"
#include "renderfarm/trace/film.h"

namespace mogao {

Rgb8Image display_frame(const RgbFloatImage& radiance, float exposure, ToneMap tone_map) {
    Rgb8Image out(radiance.size);
    to_srgb8(radiance, PixelRect::whole(radiance.size), exposure, out, tone_map);
    return out;
}

double display_psnr(const RgbFloatImage& frame, const RgbFloatImage& reference, float exposure, ToneMap tone_map) {
    return psnr(display_frame(frame, exposure, tone_map), display_frame(reference, exposure, tone_map));
}

}  // namespace mogao
