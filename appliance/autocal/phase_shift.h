// SPDX-License-Identifier: Apache-2.0
// Phase-shifted sinusoids on top of the Gray code (autocal.h, step 1b): sub-pixel projector
// positions per camera pixel where the Gray code alone gives only the centre of a block.
//
// Method (Gühring 2001, "Dense 3-D surface acquisition by structured light using off-the-shelf
// components", Proc. SPIE 4309: Gray code for the period, phase shift within it; the N-step
// phase-shift estimator of Bruning et al. 1974, Applied Optics 13(11)):
//  * Pattern i of N along one axis shows light L(X) = 1/2 + 1/2 cos(2 pi X / P - 2 pi i / N) at
//    projector image position X (pixel centre X = x + 0.5) with period P pixels. The signal is
//    L^(1 / gamma), gamma the projectors' assumed response (data sheet, 2.2): the projector's
//    response turns it back into a sinusoid of light; a wrong gamma leaves harmonics, which the N-step
//    estimator rejects up to order N - 2.
//  * A camera pixel sees I_i = a + b cos(phi - 2 pi i / N) (its footprint's average of a
//    sinusoid is a sinusoid of the same phase); with S = sum I_i sin(2 pi i / N) and
//    C = sum I_i cos(2 pi i / N): phi = atan2(S, C), b = 2 / N sqrt(S^2 + C^2) (the modulation).
//  * Unwrapping: X = X_gray + wrap_P(phi P / (2 pi) - X_gray), wrap_P into [-P/2, P/2): right
//    whenever the Gray-code position is within P/2 of the truth, i.e. its block is at most P/2.
//  * Uncertainty: for image noise sigma_n per image, sigma_phi = sigma_n sqrt(2 / N) / b (Bruning
//    et al.), so sigma_X = P / (2 pi) sigma_phi.
//  * A camera that clips: where some of a pixel's N images reach `clip_level`, those images hold full
//    scale, not a + b cos(...), and the estimator above is biased by the clipped peak's harmonics (a
//    phase error that repeats N times a period). Those images are left out and a, b cos phi and b sin phi
//    are fitted by least squares to the others (Chen & Zhang 2016, "High-quality 3D shape measurement
//    using saturated fringe patterns", Optics and Lasers in Engineering 87): at least 3 must remain. The
//    fit's noise gain g (sigma_phi = sigma_n g / b) comes from its normal matrix M: g^2 = b^2 d^T M^-1 d,
//    d the gradient of phi in (a, b sin phi, b cos phi); sqrt(2 / N) where nothing clips.
#pragma once

#include <limits>
#include <vector>

#include <opencv2/core.hpp>

#include "common/pixel_rect.h"

namespace mogao::autocal {

// Pattern i (0..shifts-1) of `shifts` along columns (rows = false) or rows: the signal in [0, 1]
// described above, CV_32FC1 of `size`. Throws std::invalid_argument for shifts < 3, i outside
// 0..shifts-1, period_px < 2 or gamma outside (0, 10].
[[nodiscard]] cv::Mat1f phase_shift_pattern(ImageSize size, bool rows, double period_px, int shifts, int i,
                                            double gamma);

struct PhaseImage {
    cv::Mat1f position;      // projector image position within the period, [0, P) pixels
    cv::Mat1f modulation;    // b, camera units; 0 where fewer than 3 images are below the clip level
    cv::Mat1f noise_gain;    // g above: sigma_phi = sigma_n g / b (sqrt(2 / N) unclipped; +inf where b is 0)
    int clipped_pixels = 0;  // pixels with at least one image at or above the clip level
};

// No clipping: every image value is used.
inline constexpr float kNoClipLevel = std::numeric_limits<float>::infinity();

// Decodes `images` (the camera's views of patterns 0..N-1, CV_32FC1, one size), leaving out per pixel the
// images at or above `clip_level`. Throws std::invalid_argument for fewer than 3 images or sizes that differ.
[[nodiscard]] PhaseImage decode_phase(const std::vector<cv::Mat1f>& images, double period_px,
                                      float clip_level = kNoClipLevel);

// The unwrapped position: x_gray (Gray-code block centre, pixels) moved to the nearest position
// congruent to `phase_position` modulo the period.
[[nodiscard]] double unwrap_position(double x_gray, double phase_position, double period_px);

// The standard deviation of Gaussian noise from absolute deviations: 1.4826 x their median (the MAD's
// consistency constant; Rousseeuw & Croux 1993). Reorders `abs_devs`; 0 when it is empty.
[[nodiscard]] double mad_sigma(std::vector<float>& abs_devs);

// Robust per-image noise of a set of N-step images (N even): the half-sum of opposite shifts,
// (I_i + I_{i+N/2}) / 2, is a for every i, so their differences are noise alone; the median
// absolute deviation over `mask` (less the pixels where one of the four images used is at or above
// `clip_level`: a clipped image breaks the identity) scaled to a Gaussian's sigma (1.4826 MAD) and to one
// image. Returns 0 for N odd or an empty mask.
[[nodiscard]] double phase_image_noise(const std::vector<cv::Mat1f>& images, const cv::Mat1b& mask,
                                       float clip_level = kNoClipLevel);

}  // namespace mogao::autocal
