// SPDX-License-Identifier: Apache-2.0
// Gray-code patterns and their decoding into projector <-> camera correspondences (autocal.h, 1).
#include "appliance/autocal/gray_code.h"

#include <algorithm>
#include <cmath>

namespace mogao::autocal {

int gray_code_bits(int extent) {
    int bits = 1;
    while ((1 << bits) < extent) ++bits;
    return bits;
}

cv::Mat1f gray_code_pattern(ImageSize size, bool rows, int bit, bool inverted) {
    const int n = gray_code_bits(rows ? size.height : size.width);
    if (bit < 0 || bit >= n)
        throw std::invalid_argument("gray_code_pattern: bit " + std::to_string(bit) + " outside 0.." +
                                    std::to_string(n - 1));
    cv::Mat1f img(size.height, size.width);
    for (int y = 0; y < size.height; ++y) {
        for (int x = 0; x < size.width; ++x) {
            const int i = rows ? y : x;
            const int gray = i ^ (i >> 1);
            const bool on = ((gray >> (n - 1 - bit)) & 1) != 0;
            img(y, x) = (on != inverted) ? 1.0f : 0.0f;
        }
    }
    return img;
}

namespace {

// Decodes one axis: captures bits from the coarsest while the camera resolves them, at most
// options.max_gray_bits of them (0 = all), each pattern and inverse the mean of
// options.frames_per_pattern frames. Returns the number of bits used. Per camera pixel, `gray` gets the Gray-code
// prefix and `depth` the number of bits it resolved: a pixel stops at its first bit with |pattern - inverse| below half
// its contrast. For the reflected Gray code that bit changes at the middle of the pixel's block of `depth` bits, so the
// block's centre is where the pixel is (Inokuchi et al. 1984; the same property makes Gray code robust at stripe
// edges). Pixels below `shadow` contrast stay at -1.
int decode_axis(PatternSource& source, int k, std::size_t projectors, ImageSize size, bool rows,
                const cv::Mat1f& contrast, const AutocalOptions& options, cv::Mat1i& code, cv::Mat1i& depth,
                int& captures) {
    const int all = gray_code_bits(rows ? size.height : size.width);
    const int n = options.max_gray_bits > 0 ? std::min(all, options.max_gray_bits) : all;
    const int frames = options.frames_per_pattern;
    cv::Mat1i gray(contrast.size(), 0);
    cv::Mat1b open(contrast.size(), 1);  // the pixel still takes bits
    int used = 0;
    for (int bit = 0; bit < n; ++bit) {
        std::vector<cv::Mat> signals(projectors);
        signals[static_cast<std::size_t>(k)] = gray_code_pattern(size, rows, bit, false);
        const cv::Mat1f on = show_averaged(source, signals, frames);
        signals[static_cast<std::size_t>(k)] = gray_code_pattern(size, rows, bit, true);
        const cv::Mat1f off = show_averaged(source, signals, frames);
        captures += 2 * frames;
        long valid = 0;
        long resolved = 0;
        for (int y = 0; y < on.rows; ++y) {
            for (int x = 0; x < on.cols; ++x) {
                if (code(y, x) < 0) continue;
                ++valid;
                resolved += std::abs(on(y, x) - off(y, x)) > 0.5f * contrast(y, x);
            }
        }
        if (valid == 0 || static_cast<double>(resolved) < options.min_bit_fraction * static_cast<double>(valid)) break;
        for (int y = 0; y < on.rows; ++y) {
            for (int x = 0; x < on.cols; ++x) {
                if (code(y, x) < 0 || !open(y, x)) continue;
                const float d = on(y, x) - off(y, x);
                if (std::abs(d) < 0.5f * contrast(y, x)) {
                    open(y, x) = 0;
                    continue;
                }
                gray(y, x) = (gray(y, x) << 1) | (d > 0.0f ? 1 : 0);
                ++depth(y, x);
            }
        }
        ++used;
    }
    // Gray -> binary prefix.
    for (int y = 0; y < code.rows; ++y) {
        for (int x = 0; x < code.cols; ++x) {
            if (code(y, x) < 0) continue;
            int g = gray(y, x);
            int b = 0;
            for (; g != 0; g >>= 1) b ^= g;
            code(y, x) = b;
        }
    }
    return used;
}

}  // namespace

Correspondences decode_projector(PatternSource& source, int k, const std::vector<ImageSize>& projectors,
                                 const AutocalOptions& options) {
    const ImageSize size = projectors.at(static_cast<std::size_t>(k));
    std::vector<cv::Mat> signals(projectors.size());
    signals[static_cast<std::size_t>(k)] = cv::Mat1f(size.height, size.width, 1.0f);
    const cv::Mat1f white = show_averaged(source, signals, options.frames_per_pattern);
    signals[static_cast<std::size_t>(k)] = cv::Mat();
    const cv::Mat1f black = show_averaged(source, signals, options.frames_per_pattern);
    Correspondences out;
    out.captures = 2 * options.frames_per_pattern;
    cv::Mat1f contrast;
    cv::subtract(white, black, contrast);
    cv::Mat1i col(contrast.size(), -1);
    for (int y = 0; y < contrast.rows; ++y) {
        for (int x = 0; x < contrast.cols; ++x) col(y, x) = contrast(y, x) > options.min_contrast ? 0 : -1;
    }
    cv::Mat1i row = col.clone();
    cv::Mat1i col_depth(contrast.size(), 0);
    cv::Mat1i row_depth(contrast.size(), 0);
    out.lit_pixels = cv::countNonZero(col == 0);
    out.column_bits =
        decode_axis(source, k, projectors.size(), size, false, contrast, options, col, col_depth, out.captures);
    out.row_bits =
        decode_axis(source, k, projectors.size(), size, true, contrast, options, row, row_depth, out.captures);
    if (out.column_bits < options.min_bits || out.row_bits < options.min_bits) return out;
    // One correspondence per decoded camera pixel with at least all but two of the resolved bits
    // per axis: its centre <-> the centre of the projector block its code names, with the block's
    // size (its uncertainty). A regular stride keeps at most `max_correspondences`.
    const int nc = gray_code_bits(size.width);
    const int nr = gray_code_bits(size.height);
    const auto usable = [&](int y, int x) {
        return col(y, x) >= 0 && row(y, x) >= 0 && col_depth(y, x) >= std::max(1, out.column_bits - 2) &&
               row_depth(y, x) >= std::max(1, out.row_bits - 2);
    };
    long valid = 0;
    for (int y = 0; y < col.rows; ++y) {
        for (int x = 0; x < col.cols; ++x) valid += usable(y, x);
    }
    const long stride = std::max<long>(1, (valid + options.max_correspondences - 1) / options.max_correspondences);
    long seen = 0;
    for (int y = 0; y < col.rows; ++y) {
        for (int x = 0; x < col.cols; ++x) {
            if (!usable(y, x) || seen++ % stride != 0) continue;
            const int cw = 1 << (nc - col_depth(y, x));
            const int ch = 1 << (nr - row_depth(y, x));
            const double px = (col(y, x) + 0.5) * cw;
            const double py = (row(y, x) + 0.5) * ch;
            if (px >= size.width || py >= size.height) continue;  // codes past the image: decoding errors
            out.camera.emplace_back(x + 0.5, y + 0.5);
            out.projector.emplace_back(px, py);
            out.block.emplace_back(cw, ch);
        }
    }
    return out;
}

}  // namespace mogao::autocal
