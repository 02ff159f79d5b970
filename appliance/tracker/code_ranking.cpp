// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/code_ranking.h"

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

double pearson(const std::vector<double>& a, const std::vector<double>& b) {
    const double n = static_cast<double>(a.size());
    double ma = 0, mb = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        ma += a[i] / n;
        mb += b[i] / n;
    }
    double sab = 0, saa = 0, sbb = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        sab += (a[i] - ma) * (b[i] - mb);
        saa += (a[i] - ma) * (a[i] - ma);
        sbb += (b[i] - mb) * (b[i] - mb);
    }
    return saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : 0.0;
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
    const std::vector<double> means = data_cell_means(image, corners, family);
    const int border = family.border_width_cells();
    const int inner = border - 2;
    const int first = (family.total_width_cells() - border) / 2 + 1;
    std::vector<CodeMatch> out;
    std::vector<double> pattern(means.size());
    for (int id = 0; id < family.code_count(); ++id) {
        const TagBitmap bitmap = make_tag_bitmap(family, id);
        for (int mirrored = 0; mirrored < 2; ++mirrored) {
            for (int rotation = 0; rotation < 4; ++rotation) {
                for (int y = 0; y < inner; ++y) {
                    for (int x = 0; x < inner; ++x) {
                        int u = mirrored ? inner - 1 - x : x, v = y;  // cell of the printed code seen at (x, y)
                        for (int q = 0; q < rotation; ++q) std::tie(u, v) = std::pair{inner - 1 - v, u};
                        pattern[static_cast<std::size_t>(y * inner + x)] = bitmap.at(first + u, first + v) / 255.0;
                    }
                }
                out.push_back({id, rotation, mirrored == 1, pearson(means, pattern)});
            }
        }
    }
    std::stable_sort(out.begin(), out.end(),
                     [](const CodeMatch& a, const CodeMatch& b) { return a.correlation > b.correlation; });
    return out;
}

}  // namespace mogao
