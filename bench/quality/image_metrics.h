// SPDX-License-Identifier: Apache-2.0
// Error of a rendered frame against a converged reference, for the quality curves (docs/quality.md).
//
// Three measures, each on the images the viewer would compare:
//  * relative_mse: on linear radiance (RgbFloatImage, scene units), the mean over all R, G, B samples
//    of (x - r)^2 / (r^2 + eps), eps = 1e-2 by default (Rousselle, Knaus, Zwicker, "Adaptive
//    sampling and reconstruction using greedy error minimization", SIGGRAPH Asia 2011, and the
//    denoising literature since). eps keeps near-black pixels from dominating; with the grotto's
//    radiance (mean ~0.1-0.5) 1e-2 weighs pixels below ~0.1 less than relatively.
//  * display_psnr_db: PSNR of sRGB8 frames, peak 255, all samples (common/image_compare.h).
//  * ssim_luminance: SSIM of Wang, Bovik, Sheikh, Simoncelli, "Image quality assessment: from error
//    visibility to structural similarity", IEEE TIP 13(4), 2004: on the luma Y = 0.299 R + 0.587 G
//    + 0.114 B of the sRGB8 values (ITU-R BT.601 weights, as MATLAB's rgb2gray in the paper's code),
//    an 11x11 circular-symmetric Gaussian window with sigma 1.5 normalised to sum 1, K1 = 0.01,
//    K2 = 0.03, L = 255, C1 = (K1 L)^2, C2 = (K2 L)^2, eq. (13); the mean SSIM (eq. 17) over every
//    pixel whose window lies inside the image (the paper's 'valid' filtering, no padding).
//    Images smaller than the window (11 px on either side) give std::invalid_argument.
// All functions throw std::invalid_argument when the sizes differ or an image is malformed.
#pragma once

#include "common/image.h"

namespace mogao::quality {

inline constexpr double kRelMseEpsilon = 1e-2;

[[nodiscard]] double relative_mse(const RgbFloatImage& x, const RgbFloatImage& reference,
                                  double epsilon = kRelMseEpsilon);

[[nodiscard]] double display_psnr_db(const Rgb8Image& x, const Rgb8Image& reference);

[[nodiscard]] double ssim_luminance(const Rgb8Image& x, const Rgb8Image& reference);

// relMSE as decibels, -10 log10(relMSE): on the same axis as PSNR (a halving of the error variance
// is +3.01 dB), for the log-log plot against spp.
[[nodiscard]] double relative_mse_db(double rel_mse);

// Bilinear resize of linear radiance (pixel centres at (x + 0.5) / W, edge-clamped), so a frame
// rendered at resolution_scale < 1 is compared with the full-size reference the way the kiosk's
// texture sampling would show it.
[[nodiscard]] RgbFloatImage resize_bilinear(const RgbFloatImage& in, ImageSize to);

}  // namespace mogao::quality
