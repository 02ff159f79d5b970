// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/encode/contact_sheet.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/codec_errors.h"

namespace mogao {
namespace {

// One source pixel's contribution to one destination pixel along an axis.
struct Tap {
    int src;
    std::int64_t weight;
};

// Box-filter taps for resampling `src_len` pixels to `dst_len`. Positions are measured in units of
// 1/dst_len source pixels, so destination pixel j covers [j*src_len, (j+1)*src_len) and source
// pixel i covers [i*dst_len, (i+1)*dst_len): every overlap is an integer and the weights of each
// destination pixel sum to exactly src_len.
struct AxisTaps {
    std::vector<Tap> taps;
    std::vector<std::size_t> begin;  // taps of destination j are [begin[j], begin[j+1])
};

AxisTaps box_taps(int src_len, int dst_len) {
    AxisTaps axis;
    axis.begin.reserve(static_cast<std::size_t>(dst_len) + 1);
    const std::int64_t s = src_len;
    const std::int64_t d = dst_len;
    for (std::int64_t j = 0; j < d; ++j) {
        axis.begin.push_back(axis.taps.size());
        const std::int64_t lo = j * s;
        const std::int64_t hi = (j + 1) * s;
        for (std::int64_t i = lo / d; i * d < hi; ++i) {
            const std::int64_t overlap = std::min(hi, (i + 1) * d) - std::max(lo, i * d);
            if (overlap > 0) axis.taps.push_back({static_cast<int>(i), overlap});
        }
    }
    axis.begin.push_back(axis.taps.size());
    return axis;
}

// Copies `thumb` into `sheet` with its top-left corner at (x0, y0).
void blit(Rgb8Image& sheet, const Rgb8Image& thumb, int x0, int y0) {
    const auto row_bytes = static_cast<std::size_t>(thumb.size.width) * 3;
    for (int y = 0; y < thumb.size.height; ++y) {
        std::memcpy(sheet.at(x0, y0 + y), thumb.at(0, y), row_bytes);
    }
}

}  // namespace

Rgb8Image downscale_box(const Rgb8Image& source, ImageSize target) {
    require_valid_image(source, "downscale_box");
    if (target.width <= 0 || target.height <= 0) {
        throw std::invalid_argument("downscale_box: empty target " + std::to_string(target.width) + "x" +
                                    std::to_string(target.height));
    }
    const int sw = source.size.width;
    const int sh = source.size.height;
    const int tw = target.width;
    const AxisTaps tx = box_taps(sw, tw);
    const AxisTaps ty = box_taps(sh, target.height);

    // Separable: horizontal pass into exact integer sums (weights sum to sw), then vertical.
    std::vector<std::int64_t> rows(static_cast<std::size_t>(tw) * static_cast<std::size_t>(sh) * 3, 0);
    for (int y = 0; y < sh; ++y) {
        std::int64_t* out = rows.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(tw) * 3;
        for (int j = 0; j < tw; ++j) {
            for (std::size_t t = tx.begin[j]; t < tx.begin[j + 1]; ++t) {
                const std::uint8_t* p = source.at(tx.taps[t].src, y);
                for (int c = 0; c < 3; ++c) out[j * 3 + c] += tx.taps[t].weight * p[c];
            }
        }
    }
    Rgb8Image result(target);
    const std::int64_t norm = std::int64_t{sw} * sh;  // at most 255 * norm per sum: no overflow below 2^55
    for (int k = 0; k < target.height; ++k) {
        for (int j = 0; j < tw; ++j) {
            std::int64_t sum[3] = {0, 0, 0};
            for (std::size_t t = ty.begin[k]; t < ty.begin[k + 1]; ++t) {
                const std::int64_t* r = rows.data() + (static_cast<std::size_t>(ty.taps[t].src) * tw + j) * 3;
                for (int c = 0; c < 3; ++c) sum[c] += ty.taps[t].weight * r[c];
            }
            std::uint8_t* dst = result.at(j, k);
            for (int c = 0; c < 3; ++c) dst[c] = static_cast<std::uint8_t>((sum[c] + norm / 2) / norm);
        }
    }
    return result;
}

Rgb8Image make_contact_sheet(std::span<const Rgb8Image> frames, int columns, int thumb_width, int border_px) {
    if (frames.empty()) throw std::invalid_argument("make_contact_sheet: no frames");
    if (columns < 1 || thumb_width < 1 || border_px < 0) {
        throw std::invalid_argument("make_contact_sheet: need columns >= 1, thumb_width >= 1, border_px >= 0 (got " +
                                    std::to_string(columns) + ", " + std::to_string(thumb_width) + ", " +
                                    std::to_string(border_px) + ")");
    }
    std::vector<Rgb8Image> thumbs;
    thumbs.reserve(frames.size());
    int cell_height = 1;
    for (const Rgb8Image& frame : frames) {
        require_valid_image(frame, "make_contact_sheet");
        // Keep the aspect ratio: height = round(thumb_width * h / w), at least one row.
        const std::int64_t w = frame.size.width;
        const std::int64_t h = std::int64_t{thumb_width} * frame.size.height;
        const auto th = static_cast<int>(std::max<std::int64_t>(1, (2 * h + w) / (2 * w)));
        thumbs.push_back(downscale_box(frame, ImageSize{thumb_width, th}));
        cell_height = std::max(cell_height, th);
    }
    const auto n = static_cast<std::int64_t>(frames.size());
    const std::int64_t cols = std::min<std::int64_t>(columns, n);
    const std::int64_t grid_rows = (n + cols - 1) / cols;
    const std::int64_t width = cols * thumb_width + (cols + 1) * border_px;
    const std::int64_t height = grid_rows * cell_height + (grid_rows + 1) * border_px;
    constexpr std::int64_t kMaxSide = 65535;  // larger sheets cannot be stored as JPEG anyway
    if (width > kMaxSide || height > kMaxSide) {
        throw std::invalid_argument("make_contact_sheet: sheet would be " + std::to_string(width) + "x" +
                                    std::to_string(height) + ", over " + std::to_string(kMaxSide) + " per side");
    }
    Rgb8Image sheet(ImageSize{static_cast<int>(width), static_cast<int>(height)}, kContactSheetBackground);
    for (std::size_t i = 0; i < thumbs.size(); ++i) {
        const auto col = static_cast<int>(static_cast<std::int64_t>(i) % cols);
        const auto row = static_cast<int>(static_cast<std::int64_t>(i) / cols);
        const int x0 = border_px + col * (thumb_width + border_px);
        const int y0 = border_px + row * (cell_height + border_px) + (cell_height - thumbs[i].size.height) / 2;
        blit(sheet, thumbs[i], x0, y0);
    }
    return sheet;
}

}  // namespace mogao
