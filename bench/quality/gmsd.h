// SPDX-License-Identifier: Apache-2.0
// Gradient magnitude similarity deviation: an error measure that counts blur and blocks, which PSNR
// and SSIM barely punish in a dark, low-contrast room.
//
// W. Xue, L. Zhang, X. Mou, A. C. Bovik, "Gradient Magnitude Similarity Deviation: A Highly
// Efficient Perceptual Image Quality Index", IEEE TIP 23(2), 2014, eqs. (1)-(4) and its reference
// code: on the luma Y = 0.299 R + 0.587 G + 0.114 B of the sRGB8 values (0..255), both images are
// averaged over 2x2 blocks and kept every second pixel (the code's 2x2 average filter then 1:2:end
// decimation; an odd last row or column is dropped); the gradient magnitude of each is
//     m = sqrt((Y * h_x)^2 + (Y * h_y)^2),  h_x = [1 0 -1; 1 0 -1; 1 0 -1] / 3,  h_y = h_x^T
// (Prewitt); the similarity map is GMS = (2 m_r m_d + c) / (m_r^2 + m_d^2 + c), c = 170 (the
// paper's constant for 8-bit images); GMSD is the population standard deviation of GMS. Unlike
// the code (conv2 'same', zero padding) the map covers only pixels whose 3x3 neighbourhood lies
// inside the decimated image, so the frame's border is not read as an edge.
// Range [0, 1): 0 for identical images, larger is worse. Lower-contrast edges in the distorted
// frame (blur, the blocks of a small frame upsampled) lower GMS at the edges and leave it at 1 in
// flat areas: the deviation grows.
// Throws std::invalid_argument when the sizes differ, a buffer does not match its size, or the
// decimated image is smaller than 3x3 (frames under 6x6 pixels).
#pragma once

#include "common/image.h"

namespace mogao::quality {

inline constexpr double kGmsdConstant = 170.0;

[[nodiscard]] double gmsd(const Rgb8Image& x, const Rgb8Image& reference);

}  // namespace mogao::quality
