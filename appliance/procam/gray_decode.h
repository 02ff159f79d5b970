// SPDX-License-Identifier: Apache-2.0
// Gray-code structured light for a projector-camera pair on the bench: the patterns, in the order of
// OpenCV's cv::structured_light::GrayCodePattern::generate (the order real captures come in), and
// our per-pixel decoder.
//
// Patterns (a W x H projector): column bits Bc = ceil(log2 W), row bits Br = ceil(log2 H). Image
// 2 i is bit (Bc - 1 - i) of the reflected binary (Gray) code g(x) = x ^ (x >> 1) of the projector
// column x (most significant bit first, white = 1) and image 2 i + 1 its inverse, i = 0 .. Bc - 1;
// images 2 Bc + 2 j and 2 Bc + 2 j + 1 the same for the row y. Then one all-white image (index
// 2 (Bc + Br)) and one all-black image (the next). Gray code: F. Gray, US patent 2,632,058 (1953);
// its use for structured light: Inokuchi, Sato & Matsuda, ICPR 1984.
//
// Decoding (per camera pixel, 8-bit grey captures):
//   lit       white - black >= shadow_threshold (grey levels): the projector reaches the pixel with
//             enough contrast; elsewhere (shadow, dark board squares under dim light, the floor) the
//             pixel is not decoded;
//   bit       pattern > inverse; the pair must differ by at least
//             max(min_bit_contrast, bit_contrast_fraction * (white - black)), else the bit is
//             ambiguous (a stripe edge falls on the pixel) and the pixel is not decoded;
//   position  binary from Gray (b_k = b_{k+1} ^ g_k from the most significant bit down); a code at
//             or beyond the projector's width (height) is not decoded.
// The comparison of each pattern with its inverse, not with a global threshold, makes the decoder
// indifferent to the surface's albedo and the projector's vignetting (Salvi, Pagès & Batlle,
// "Pattern codification strategies in structured light systems", Pattern Recognition 37(4), 2004).
//
// Positions are projector pixel indices; in OpenCV's convention (pixel centre at integer
// coordinates) index x is the stripe's centre.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "common/pixel_rect.h"

namespace mogao::procam {

struct GrayLayout {
    ImageSize projector;
    int column_bits = 0;
    int row_bits = 0;
    [[nodiscard]] int pattern_count() const { return 2 * (column_bits + row_bits); }
    [[nodiscard]] int white_index() const { return pattern_count(); }
    [[nodiscard]] int black_index() const { return pattern_count() + 1; }
    [[nodiscard]] int image_count() const { return pattern_count() + 2; }
};

// Throws std::invalid_argument unless 2 <= width, height <= 16384.
[[nodiscard]] GrayLayout gray_layout(ImageSize projector);

// The layout's image_count() projector images, CV_8U, in the order above.
[[nodiscard]] std::vector<cv::Mat> render_gray_patterns(ImageSize projector);

struct DecodeOptions {
    double shadow_threshold = 40.0;      // white - black, grey levels (OpenCV's sample uses 40)
    double min_bit_contrast = 5.0;       // |pattern - inverse|, grey levels (OpenCV's sample: 5)
    double bit_contrast_fraction = 0.0;  // of (white - black), per pixel
};

struct DecodedPixels {
    cv::Mat projector;  // CV_32SC2, camera size: (x, y) projector pixel indices, (-1, -1) where not decoded
    int lit_pixels = 0;
    int decoded_pixels = 0;
    [[nodiscard]] bool decoded(int x, int y) const { return projector.at<cv::Vec2i>(y, x)[0] >= 0; }
};

// `captures`: the layout's image_count() camera images, CV_8U, all of one size, in the patterns'
// order. Throws std::invalid_argument naming the image index and the expected count, type or size.
[[nodiscard]] DecodedPixels decode_gray(const std::vector<cv::Mat>& captures, const GrayLayout& layout,
                                        const DecodeOptions& options = {});

}  // namespace mogao::procam
