// SPDX-License-Identifier: Apache-2.0
#include "common/image_compare.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>

#include "common/codec_errors.h"

namespace mogao {
namespace {

void require_same_size(const Rgb8Image& a, const Rgb8Image& b, const char* who) {
    require_valid_image(a, who);
    require_valid_image(b, who);
    if (a.size != b.size) {
        throw std::invalid_argument(std::string(who) + ": sizes differ (" + std::to_string(a.size.width) + "x" +
                                    std::to_string(a.size.height) + " vs " + std::to_string(b.size.width) + "x" +
                                    std::to_string(b.size.height) + ")");
    }
}

}  // namespace

double psnr(const Rgb8Image& a, const Rgb8Image& b) {
    require_same_size(a, b, "psnr");
    // Exact integer sum of squares: at most 255^2 * 3 * 16384^2 per frame-sized image, far below 2^63.
    std::uint64_t sum_sq = 0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) {
        const int d = int{a.pixels[i]} - int{b.pixels[i]};
        sum_sq += static_cast<std::uint64_t>(d * d);
    }
    if (sum_sq == 0) return std::numeric_limits<double>::infinity();
    const double mse = static_cast<double>(sum_sq) / static_cast<double>(a.pixels.size());
    return 10.0 * std::log10(255.0 * 255.0 / mse);
}

double max_abs_difference(const Rgb8Image& a, const Rgb8Image& b) {
    require_same_size(a, b, "max_abs_difference");
    int worst = 0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) {
        worst = std::max(worst, std::abs(int{a.pixels[i]} - int{b.pixels[i]}));
    }
    return worst;
}

std::int64_t count_differing_pixels(const Rgb8Image& a, const Rgb8Image& b, int tolerance) {
    require_same_size(a, b, "count_differing_pixels");
    if (tolerance < 0) throw std::invalid_argument("count_differing_pixels: negative tolerance");
    std::int64_t count = 0;
    for (std::size_t i = 0; i < a.pixels.size(); i += 3) {
        bool differs = false;
        for (std::size_t c = 0; c < 3; ++c) {
            differs = differs || std::abs(int{a.pixels[i + c]} - int{b.pixels[i + c]}) > tolerance;
        }
        count += differs ? 1 : 0;
    }
    return count;
}

}  // namespace mogao
