// SPDX-License-Identifier: Apache-2.0
// The light a projector's pixels put at a continuous position of its image, for the ground truth of what a viewer
// sees (rig_bridge.h's measure_luminance, colour_truth.h): each pixel's light spread by its aperture (a box one pixel
// wide, the panel's fill factor taken as 1) convolved with the lens's defocus (a Gaussian of standard deviation
// RigProjector::blur_px projector pixels, as virtual_rig.h's camera sees it). Separable:
//   L(x, y) = sum_q,r v_qr Kx(x - q - 1/2) Ky(y - r - 1/2),
//   K(t) = Phi((t + 1/2) / sigma) - Phi((t - 1/2) / sigma)   (Phi the standard normal CDF),
// in image positions (pixel q's centre at q + 1/2); pixels beyond the image give no light (virtual_rig.h: light
// spread beyond the border is lost). With sigma = 0, K is the box: the pixel that contains the position, as
// output_pixel gives it. A linear ramp of pixel values stays a continuous ramp of light under K for sigma > 0, up to
// a ripple of about exp(-2 pi^2 sigma^2) / pi of one pixel's step (0.013 at sigma 0.4, under 1e-4 from 0.7), so two
// projectors whose blend weights sum to 1 at their pixel centres sum to 1 between them as well, up to the ramps'
// curvature; with sigma = 0 each pixel's light is a step.
#pragma once

#include <array>
#include <cstddef>

namespace mogao::autocal {

struct FootprintTaps {
    static constexpr int kMaxTaps = 112;  // blur_px <= 10 (rig_model.h's range): at most 10 sigma + 3 pixels
    int first = 0;                        // the first pixel index with a weight (may be outside the image)
    int count = 0;
    std::array<double, kMaxTaps> weight{};
};

// The pixels along one axis of `extent` pixels whose light reaches image position t, and their weights K, cut at
// +-5 sigma and to [0, extent) (so the weights sum to less than 1 within 5 sigma of the border). sigma in [0, 10];
// sigma = 0 gives the one pixel floor(t) (clamped to the image) with weight 1.
[[nodiscard]] FootprintTaps footprint_taps(double t, int extent, double sigma);

// Calls add(i, weight) for each pixel of a `width` x `height` image (i its row-major index) whose light reaches
// image position (x, y), with its weight Kx Ky (footprint_taps along each axis).
template <class Add>
void for_each_footprint_pixel(double x, double y, int width, int height, double sigma, Add&& add) {
    const FootprintTaps tx = footprint_taps(x, width, sigma);
    const FootprintTaps ty = footprint_taps(y, height, sigma);
    for (int j = 0; j < ty.count; ++j) {
        const std::size_t row = static_cast<std::size_t>(ty.first + j) * static_cast<std::size_t>(width);
        for (int i = 0; i < tx.count; ++i) {
            add(row + static_cast<std::size_t>(tx.first + i),
                ty.weight[static_cast<std::size_t>(j)] * tx.weight[static_cast<std::size_t>(i)]);
        }
    }
}

}  // namespace mogao::autocal
