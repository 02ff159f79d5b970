// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/lab/code_ranking.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "appliance/tracker/tag_bitmap.h"

namespace mogao {
namespace {

// Mean grey of the central half of each data cell of the rectified tag, row-major from the top.
std::vector<double> data_cell_means(const GrayImage& image, const TagCorners& corners, const TagFamily& family) {
    const int cells = family.total_width_cells();
    const int border = family.border_width_cells();
    const double b0 = (cells - border) / 2.0;  // the black square starts b0 cells in
    const double s = kRankCellPx;
    // corners[0..3] = tag (-1, 1), (1, 1), (1, -1), (-1, -1), x right and y down; OpenCV puts
    // pixel centres at integers, so both sides shift by -0.5.
    const double lo = b0 * s - 0.5;
    const double hi = (b0 + border) * s - 0.5;
    std::vector<cv::Point2f> src,
        dst{{float(lo), float(hi)}, {float(hi), float(hi)}, {float(hi), float(lo)}, {float(lo), float(lo)}};
    for (const auto& c : corners) src.emplace_back(float(c.x() - 0.5), float(c.y() - 0.5));
    const cv::Mat h = cv::getPerspectiveTransform(src, dst);
    const cv::Mat view(image.height, image.width, CV_8UC1, const_cast<std::uint8_t*>(image.pixels.data()));
    cv::Mat rectified;
    cv::warpPerspective(view, rectified, h, cv::Size(cells * kRankCellPx, cells * kRankCellPx), cv::INTER_LINEAR,
                        cv::BORDER_REPLICATE);
    const int inner = border - 2;
    const int first = static_cast<int>(b0) + 1;
    std::vector<double> means;
    for (int y = 0; y < inner; ++y) {
        for (int x = 0; x < inner; ++x) {
            const cv::Rect r((first + x) * kRankCellPx + kRankCellPx / 4, (first + y) * kRankCellPx + kRankCellPx / 4,
                             kRankCellPx / 2, kRankCellPx / 2);
            means.push_back(cv::mean(rectified(r))[0]);
        }
    }
    return means;
}

// Cell index maps of the 8 hypotheses' orientations: orientation[o][y * inner + x] is the cell of
// the printed code seen at (x, y); o = 4 * mirrored + quarter turns.
std::vector<std::vector<int>> orientations(int inner) {
    std::vector<std::vector<int>> out;
    for (int mirrored = 0; mirrored < 2; ++mirrored) {
        for (int rotation = 0; rotation < 4; ++rotation) {
            std::vector<int> map;
            for (int y = 0; y < inner; ++y) {
                for (int x = 0; x < inner; ++x) {
                    int u = mirrored ? inner - 1 - x : x, v = y;
                    for (int q = 0; q < rotation; ++q) std::tie(u, v) = std::pair{inner - 1 - v, u};
                    map.push_back(v * inner + u);
                }
            }
            out.push_back(std::move(map));
        }
    }
    return out;
}

// `values` less their mean, scaled to unit norm (all zeros when they are constant): Pearson's
// correlation of two such vectors is their dot product.
std::vector<double> standardised(std::vector<double> values) {
    double mean = 0, norm = 0;
    for (double v : values) mean += v / static_cast<double>(values.size());
    for (double& v : values) {
        v -= mean;
        norm += v * v;
    }
    for (double& v : values) v = norm > 0 ? v / std::sqrt(norm) : 0.0;
    return values;
}

}  // namespace

std::vector<CodeMatch> rank_codes(const GrayImage& image, const TagCorners& corners, const TagFamily& family) {
    if (!image.valid()) throw std::invalid_argument("rank_codes: invalid grey image");
    for (std::size_t k = 0; k < 4; ++k) {
        const auto& a = corners[k];
        const auto& b = corners[(k + 1) % 4];
        if (!a.allFinite()) throw std::invalid_argument("rank_codes: a corner is not finite");
        if ((a - b).norm() < 4.0) throw std::invalid_argument("rank_codes: a quad side is under 4 px");
    }
    const std::vector<double> means = standardised(data_cell_means(image, corners, family));
    const int border = family.border_width_cells();
    const int inner = border - 2;
    const int first = (family.total_width_cells() - border) / 2 + 1;
    const auto maps = orientations(inner);
    std::vector<CodeMatch> out;
    std::vector<double> cells(means.size()), pattern(means.size());
    for (int id = 0; id < family.code_count(); ++id) {
        const TagBitmap bitmap = make_tag_bitmap(family, id);
        for (int v = 0; v < inner; ++v) {
            for (int u = 0; u < inner; ++u)
                cells[static_cast<std::size_t>(v * inner + u)] = bitmap.at(first + u, first + v);
        }
        for (std::size_t o = 0; o < maps.size(); ++o) {
            for (std::size_t i = 0; i < pattern.size(); ++i) pattern[i] = cells[static_cast<std::size_t>(maps[o][i])];
            const std::vector<double> code = standardised(pattern);
            double correlation = 0;
            for (std::size_t i = 0; i < code.size(); ++i) correlation += code[i] * means[i];
            out.push_back({id, static_cast<int>(o % 4), o >= 4, correlation});
        }
    }
    std::stable_sort(out.begin(), out.end(),
                     [](const CodeMatch& a, const CodeMatch& b) { return a.correlation > b.correlation; });
    return out;
}

}  // namespace mogao
