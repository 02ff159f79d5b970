// SPDX-License-Identifier: Apache-2.0
// Gray-code patterns and our per-pixel decoder (gray_decode.h).
#include "appliance/procam/gray_decode.h"

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace mogao::procam {

namespace {

int bits_for(int n) {
    int bits = 0;
    while ((1 << bits) < n) ++bits;
    return bits;
}

// Writes the 2 * bits stripe images of one axis (columns if `columns`) starting at `first`.
void render_axis(std::vector<cv::Mat>& out, int first, int bits, bool columns, ImageSize size) {
    for (int i = 0; i < bits; ++i) {
        const int bit = bits - 1 - i;
        cv::Mat& pattern = out[static_cast<std::size_t>(first + 2 * i)];
        cv::Mat& inverse = out[static_cast<std::size_t>(first + 2 * i + 1)];
        for (int y = 0; y < size.height; ++y) {
            auto* p = pattern.ptr<std::uint8_t>(y);
            auto* q = inverse.ptr<std::uint8_t>(y);
            for (int x = 0; x < size.width; ++x) {
                const int v = columns ? x : y;
                const bool on = (((v ^ (v >> 1)) >> bit) & 1) != 0;
                p[x] = on ? 255 : 0;
                q[x] = on ? 0 : 255;
            }
        }
    }
}

void check_captures(const std::vector<cv::Mat>& captures, const GrayLayout& layout) {
    if (static_cast<int>(captures.size()) != layout.image_count()) {
        throw std::invalid_argument("decode_gray: captures must hold " + std::to_string(layout.image_count()) +
                                    " images for a " + std::to_string(layout.projector.width) + "x" +
                                    std::to_string(layout.projector.height) + " projector, got " +
                                    std::to_string(captures.size()));
    }
    for (std::size_t i = 0; i < captures.size(); ++i) {
        if (captures[i].type() != CV_8UC1 || captures[i].size() != captures[0].size() || captures[i].empty()) {
            throw std::invalid_argument("decode_gray: capture " + std::to_string(i) +
                                        " must be a non-empty CV_8U image of the first one's size");
        }
    }
}

// Decodes one axis at pixel x of a row: the projector index, or -1 if a bit is ambiguous.
int decode_axis(const std::vector<const std::uint8_t*>& rows, int first, int bits, int x, double min_contrast,
                int limit) {
    int binary = 0;
    int previous = 0;
    for (int i = 0; i < bits; ++i) {
        const int p = rows[static_cast<std::size_t>(first + 2 * i)][x];
        const int q = rows[static_cast<std::size_t>(first + 2 * i + 1)][x];
        if (std::abs(p - q) < min_contrast) return -1;
        previous ^= (p > q) ? 1 : 0;
        binary = (binary << 1) | previous;
    }
    return binary < limit ? binary : -1;
}

}  // namespace

GrayLayout gray_layout(ImageSize projector) {
    if (projector.width < 2 || projector.height < 2 || projector.width > 16384 || projector.height > 16384) {
        throw std::invalid_argument("gray_layout: projector size " + std::to_string(projector.width) + "x" +
                                    std::to_string(projector.height) + " must be within 2..16384 per side");
    }
    return GrayLayout{projector, bits_for(projector.width), bits_for(projector.height)};
}

std::vector<cv::Mat> render_gray_patterns(ImageSize projector) {
    const GrayLayout layout = gray_layout(projector);
    std::vector<cv::Mat> out;
    for (int i = 0; i < layout.image_count(); ++i) out.emplace_back(projector.height, projector.width, CV_8UC1);
    render_axis(out, 0, layout.column_bits, true, projector);
    render_axis(out, 2 * layout.column_bits, layout.row_bits, false, projector);
    out[static_cast<std::size_t>(layout.white_index())].setTo(255);
    out[static_cast<std::size_t>(layout.black_index())].setTo(0);
    return out;
}

DecodedPixels decode_gray(const std::vector<cv::Mat>& captures, const GrayLayout& layout,
                          const DecodeOptions& options) {
    check_captures(captures, layout);
    const cv::Size size = captures[0].size();
    DecodedPixels d;
    d.projector = cv::Mat(size, CV_32SC2, cv::Scalar(-1, -1));
    std::vector<const std::uint8_t*> rows(captures.size());
    for (int y = 0; y < size.height; ++y) {
        for (std::size_t i = 0; i < captures.size(); ++i) rows[i] = captures[i].ptr<std::uint8_t>(y);
        const std::uint8_t* white = rows[static_cast<std::size_t>(layout.white_index())];
        const std::uint8_t* black = rows[static_cast<std::size_t>(layout.black_index())];
        auto* out = d.projector.ptr<cv::Vec2i>(y);
        for (int x = 0; x < size.width; ++x) {
            const double range = static_cast<double>(white[x]) - static_cast<double>(black[x]);
            if (range < options.shadow_threshold) continue;
            ++d.lit_pixels;
            const double contrast = std::max(options.min_bit_contrast, options.bit_contrast_fraction * range);
            const int px = decode_axis(rows, 0, layout.column_bits, x, contrast, layout.projector.width);
            if (px < 0) continue;
            const int py =
                decode_axis(rows, 2 * layout.column_bits, layout.row_bits, x, contrast, layout.projector.height);
            if (py < 0) continue;
            out[x] = cv::Vec2i(px, py);
            ++d.decoded_pixels;
        }
    }
    return d;
}

}  // namespace mogao::procam
