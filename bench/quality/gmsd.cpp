// SPDX-License-Identifier: Apache-2.0
#include "bench/quality/gmsd.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace mogao::quality {
namespace {

struct Plane {
    int width = 0, height = 0;
    std::vector<double> v;
    [[nodiscard]] double at(int x, int y) const { return v[std::size_t(y) * width + x]; }
};

// The luma of `im`, averaged over 2x2 blocks and decimated by 2 (the paper's code).
Plane decimated_luma(const Rgb8Image& im) {
    Plane p{im.size.width / 2, im.size.height / 2, {}};
    p.v.resize(std::size_t(p.width) * p.height);
    const auto y = [&im](int x, int row) {
        const std::uint8_t* px = im.at(x, row);
        return 0.299 * px[0] + 0.587 * px[1] + 0.114 * px[2];
    };
    for (int r = 0; r < p.height; ++r)
        for (int c = 0; c < p.width; ++c)
            p.v[std::size_t(r) * p.width + c] =
                0.25 * (y(2 * c, 2 * r) + y(2 * c + 1, 2 * r) + y(2 * c, 2 * r + 1) + y(2 * c + 1, 2 * r + 1));
    return p;
}

// Prewitt gradient magnitude at an interior pixel.
double gradient_magnitude(const Plane& p, int x, int y) {
    double gx = 0, gy = 0;
    for (int k = -1; k <= 1; ++k) {
        gx += p.at(x - 1, y + k) - p.at(x + 1, y + k);
        gy += p.at(x + k, y - 1) - p.at(x + k, y + 1);
    }
    return std::sqrt(gx * gx + gy * gy) / 3.0;
}

}  // namespace

double gmsd(const Rgb8Image& x, const Rgb8Image& reference) {
    if (x.size.width != reference.size.width || x.size.height != reference.size.height)
        throw std::invalid_argument("gmsd: image is " + std::to_string(x.size.width) + "x" +
                                    std::to_string(x.size.height) + ", reference " +
                                    std::to_string(reference.size.width) + "x" + std::to_string(reference.size.height));
    const auto n = static_cast<std::size_t>(reference.size.pixel_count()) * 3;
    if (x.pixels.size() != n || reference.pixels.size() != n)
        throw std::invalid_argument("gmsd: pixel buffer length does not match the size");
    if (x.size.width < 6 || x.size.height < 6)
        throw std::invalid_argument("gmsd: images of " + std::to_string(x.size.width) + "x" +
                                    std::to_string(x.size.height) + " are under the 6x6 pixels it needs");
    const Plane d = decimated_luma(x), r = decimated_luma(reference);
    double sum = 0, sum_sq = 0;
    std::size_t count = 0;
    for (int y = 1; y + 1 < d.height; ++y)
        for (int c = 1; c + 1 < d.width; ++c) {
            const double md = gradient_magnitude(d, c, y), mr = gradient_magnitude(r, c, y);
            const double gms = (2 * mr * md + kGmsdConstant) / (mr * mr + md * md + kGmsdConstant);
            sum += gms;
            sum_sq += gms * gms;
            ++count;
        }
    const double mean = sum / double(count);
    return std::sqrt(std::max(0.0, sum_sq / double(count) - mean * mean));
}

}  // namespace mogao::quality
