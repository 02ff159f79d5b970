// SPDX-License-Identifier: Apache-2.0
// The mip chain of a texture (texture.h): box filter over linear light, one level from the one
// before, in float so that sRGB8 rounding does not compound down the chain.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>

#include "common/srgb.h"
#include "renderfarm/scene/texture.h"

namespace mogao {
namespace {

struct LinearLevel {
    int width = 0, height = 0;
    std::vector<float> rgb;  // width * height * 3
};

// Source texels [first, last] of destination texel i when a side of n texels halves to max(1, n/2):
// pairs, the last box taking an odd side's last texel as well.
struct Span {
    int first, last;
};
Span box_of(int i, int n, int halved) {
    const int first = std::min(2 * i, n - 1);
    const int last = i == halved - 1 ? n - 1 : 2 * i + 1;
    return {first, last};
}

LinearLevel halve(const LinearLevel& src) {
    LinearLevel dst;
    dst.width = std::max(1, src.width / 2);
    dst.height = std::max(1, src.height / 2);
    dst.rgb.assign(static_cast<std::size_t>(dst.width) * static_cast<std::size_t>(dst.height) * 3, 0.0f);
    for (int y = 0; y < dst.height; ++y) {
        const Span ys = box_of(y, src.height, dst.height);
        for (int x = 0; x < dst.width; ++x) {
            const Span xs = box_of(x, src.width, dst.width);
            float sum[3] = {0.0f, 0.0f, 0.0f};
            for (int j = ys.first; j <= ys.last; ++j) {
                for (int i = xs.first; i <= xs.last; ++i) {
                    const float* p = &src.rgb[(static_cast<std::size_t>(j) * static_cast<std::size_t>(src.width) +
                                               static_cast<std::size_t>(i)) *
                                              3];
                    for (int c = 0; c < 3; ++c) sum[c] += p[c];
                }
            }
            const float n = static_cast<float>((ys.last - ys.first + 1) * (xs.last - xs.first + 1));
            float* out = &dst.rgb[(static_cast<std::size_t>(y) * static_cast<std::size_t>(dst.width) +
                                   static_cast<std::size_t>(x)) *
                                  3];
            for (int c = 0; c < 3; ++c) out[c] = sum[c] / n;
        }
    }
    return dst;
}

Rgb8Image encode(const LinearLevel& level) {
    Rgb8Image image(ImageSize{level.width, level.height});
    for (std::size_t k = 0; k < level.rgb.size(); ++k) image.pixels[k] = srgb8_encode(level.rgb[k]);
    return image;
}

}  // namespace

std::vector<Rgb8Image> make_mip_chain(const Rgb8Image& level0) {
    const ImageSize size = level0.size;
    if (size.width < 1 || size.height < 1 || level0.pixels.size() != static_cast<std::size_t>(size.pixel_count()) * 3) {
        throw std::invalid_argument("make_mip_chain: the image is empty or its pixels do not match its size");
    }
    std::vector<Rgb8Image> chain;
    if (size.width == 1 && size.height == 1) return chain;
    const auto& lut = srgb8_decode_table();
    LinearLevel level{size.width, size.height, std::vector<float>(level0.pixels.size())};
    std::transform(level0.pixels.begin(), level0.pixels.end(), level.rgb.begin(),
                   [&](std::uint8_t c) { return lut[c]; });
    while (level.width > 1 || level.height > 1) {
        level = halve(level);
        chain.push_back(encode(level));
    }
    return chain;
}

}  // namespace mogao
