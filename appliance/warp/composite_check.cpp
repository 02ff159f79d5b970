// SPDX-License-Identifier: Apache-2.0
#include "appliance/warp/composite_check.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mogao {
namespace {

void require_same(const RgbFloatImage& a, const RgbFloatImage& b, const char* who) {
    const auto ok = [](const RgbFloatImage& m) {
        return m.pixels.size() == static_cast<std::size_t>(m.size.pixel_count()) * 3;
    };
    if (!(a.size == b.size) || !ok(a) || !ok(b)) {
        throw std::invalid_argument(std::string(who) + ": images must have the same size and width*height*3 values (" +
                                    std::to_string(a.size.width) + "x" + std::to_string(a.size.height) + " vs " +
                                    std::to_string(b.size.width) + "x" + std::to_string(b.size.height) + ")");
    }
}

}  // namespace

ImageDifference compare_images(const RgbFloatImage& a, const RgbFloatImage& b, PixelRect region) {
    require_same(a, b, "compare_images");
    const PixelRect r = intersect(region, PixelRect::whole(a.size));
    ImageDifference d;
    double sum = 0.0;
    for (int y = r.y0; y < r.y1; ++y) {
        for (int x = r.x0; x < r.x1; ++x) {
            const float* pa = a.at(x, y);
            const float* pb = b.at(x, y);
            for (int c = 0; c < 3; ++c) {
                const double e = std::abs(static_cast<double>(pa[c]) - pb[c]);
                sum += e;
                if (e > d.max_abs || (std::isnan(e) && d.max_x < 0)) {
                    d.max_abs = std::isnan(e) ? INFINITY : e;  // NaN is never "equal"
                    d.max_x = x;
                    d.max_y = y;
                }
            }
        }
    }
    if (!r.empty()) d.mean_abs = sum / (static_cast<double>(r.area()) * 3.0);
    return d;
}

double seam_step(const RgbFloatImage& composite, const RgbFloatImage& content, int column, int row0, int row1) {
    require_same(composite, content, "seam_step");
    if (column < 1 || column >= composite.size.width) {
        throw std::invalid_argument("seam_step: column " + std::to_string(column) + " is outside [1, " +
                                    std::to_string(composite.size.width) + ")");
    }
    double step = 0.0;
    for (int y = std::max(0, row0); y < std::min(row1, composite.size.height); ++y) {
        for (int c = 0; c < 3; ++c) {
            const double left = static_cast<double>(composite.at(column - 1, y)[c]) - content.at(column - 1, y)[c];
            const double right = static_cast<double>(composite.at(column, y)[c]) - content.at(column, y)[c];
            const double d = std::abs(right - left);
            if (!(d <= step)) step = std::isnan(d) ? INFINITY : d;  // NaN must fail, not vanish
        }
    }
    return step;
}

}  // namespace mogao
