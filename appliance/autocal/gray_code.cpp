// SPDX-License-Identifier: Apache-2.0
// Gray-code patterns and their decoding into projector <-> camera correspondences (autocal.h, 1).
#include "appliance/autocal/gray_code.h"

#include <algorithm>
#include <cmath>
#include <map>

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

// Decodes one axis: captures bits from the coarsest while the camera resolves them. Returns the
// number of bits used; `code` gets the binary prefix of the index per camera pixel (-1 = invalid).
int decode_axis(PatternSource& source, int k, std::size_t projectors, ImageSize size, bool rows,
                const cv::Mat1f& contrast, const AutocalOptions& options, cv::Mat1i& code, int& captures) {
    const int n = gray_code_bits(rows ? size.height : size.width);
    cv::Mat1i gray(contrast.size(), 0);
    int used = 0;
    for (int bit = 0; bit < n; ++bit) {
        std::vector<cv::Mat> signals(projectors);
        signals[static_cast<std::size_t>(k)] = gray_code_pattern(size, rows, bit, false);
        const cv::Mat1f on = source.show(signals);
        signals[static_cast<std::size_t>(k)] = gray_code_pattern(size, rows, bit, true);
        const cv::Mat1f off = source.show(signals);
        captures += 2;
        long valid = 0;
        long resolved = 0;
        for (int y = 0; y < on.rows; ++y) {
            for (int x = 0; x < on.cols; ++x) {
                if (code(y, x) < 0) continue;
                ++valid;
                const float d = on(y, x) - off(y, x);
                resolved += std::abs(d) > 0.5f * contrast(y, x);
            }
        }
        if (valid == 0 || static_cast<double>(resolved) < options.min_bit_fraction * static_cast<double>(valid)) break;
        for (int y = 0; y < on.rows; ++y) {
            for (int x = 0; x < on.cols; ++x) {
                if (code(y, x) < 0) continue;
                const float d = on(y, x) - off(y, x);
                if (std::abs(d) < 0.15f * contrast(y, x)) {
                    code(y, x) = -1;  // too close to call: a stripe edge crosses this pixel
                    continue;
                }
                gray(y, x) = (gray(y, x) << 1) | (d > 0.0f ? 1 : 0);
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

// One correspondence per cell (column block, row block) of `cbits` x `rbits` prefix bits whose
// camera pixels and 4 neighbours' were seen (>= 3 pixels each).
void make_cells(const cv::Mat1i& col, const cv::Mat1i& row, ImageSize size, int cbits, int rbits, int drop,
                Correspondences& out) {
    if (cbits < 1 || rbits < 1) return;
    const int cw = 1 << (gray_code_bits(size.width) - cbits);
    const int ch = 1 << (gray_code_bits(size.height) - rbits);
    struct Acc {
        double x = 0.0, y = 0.0;
        int n = 0;
    };
    std::map<std::pair<int, int>, Acc> cells;
    for (int y = 0; y < col.rows; ++y) {
        for (int x = 0; x < col.cols; ++x) {
            if (col(y, x) < 0 || row(y, x) < 0) continue;
            Acc& a = cells[{col(y, x) >> drop, row(y, x) >> drop}];
            a.x += x + 0.5;
            a.y += y + 0.5;
            ++a.n;
        }
    }
    const auto full = [&](int c, int r) {
        const auto it = cells.find({c, r});
        return it != cells.end() && it->second.n >= 3;
    };
    for (const auto& [key, a] : cells) {
        const auto [c, r] = key;
        // Only cells inside the image whose neighbours were all seen: a cell cut by the screen's
        // edge or a shadow would pull its centroid.
        if ((c + 1) * cw > size.width || (r + 1) * ch > size.height) continue;
        if (!full(c, r) || !full(c - 1, r) || !full(c + 1, r) || !full(c, r - 1) || !full(c, r + 1)) continue;
        out.camera.emplace_back(a.x / a.n, a.y / a.n);
        out.projector.emplace_back((c + 0.5) * cw, (r + 0.5) * ch);
    }
}

}  // namespace

Correspondences decode_projector(PatternSource& source, int k, const std::vector<ImageSize>& projectors,
                                 const AutocalOptions& options) {
    const ImageSize size = projectors.at(static_cast<std::size_t>(k));
    std::vector<cv::Mat> signals(projectors.size());
    signals[static_cast<std::size_t>(k)] = cv::Mat1f(size.height, size.width, 1.0f);
    const cv::Mat1f white = source.show(signals);
    signals[static_cast<std::size_t>(k)] = cv::Mat();
    const cv::Mat1f black = source.show(signals);
    Correspondences out;
    out.captures = 2;
    cv::Mat1f contrast;
    cv::subtract(white, black, contrast);
    cv::Mat1i col(contrast.size(), -1);
    for (int y = 0; y < contrast.rows; ++y) {
        for (int x = 0; x < contrast.cols; ++x) col(y, x) = contrast(y, x) > options.min_contrast ? 0 : -1;
    }
    cv::Mat1i row = col.clone();
    out.lit_pixels = cv::countNonZero(col == 0);
    out.column_bits = decode_axis(source, k, projectors.size(), size, false, contrast, options, col, out.captures);
    out.row_bits = decode_axis(source, k, projectors.size(), size, true, contrast, options, row, out.captures);
    if (out.column_bits < options.min_bits || out.row_bits < options.min_bits) return out;
    // Cells of 2^drop finer blocks merged: the drop giving the most complete cells wins (cells a
    // camera pixel or two wide have no usable centroid).
    Correspondences best = out;
    for (int drop = 0; drop <= 4; ++drop) {
        Correspondences c = out;
        make_cells(col, row, size, out.column_bits - drop, out.row_bits - drop, drop, c);
        if (c.camera.size() > best.camera.size()) best = std::move(c);
    }
    return best;
}

}  // namespace mogao::autocal
