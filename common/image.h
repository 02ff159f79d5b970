// SPDX-License-Identifier: Apache-2.0
// Frame buffers exchanged between the trace, encode and farm stages.
//
// Layout: row-major, top row first, channels interleaved (R, G, B), no padding between rows.
// Rgb8Image holds display-referred sRGB-encoded 8-bit values (IEC 61966-2-1); RgbFloatImage holds
// scene-referred linear radiance (W·sr⁻¹·m⁻² up to the scene's arbitrary photometric scale).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "pixel_rect.h"

namespace mogao {

template <typename T>
struct RgbImage {
    ImageSize size;
    std::vector<T> pixels;  // size.width * size.height * 3 values

    RgbImage() = default;
    explicit RgbImage(ImageSize s, T fill = T{})
        : size(s), pixels(static_cast<std::size_t>(s.pixel_count()) * 3, fill) {}

    [[nodiscard]] std::size_t index(int x, int y) const {
        return (static_cast<std::size_t>(y) * static_cast<std::size_t>(size.width) + static_cast<std::size_t>(x)) * 3;
    }
    [[nodiscard]] T* at(int x, int y) { return pixels.data() + index(x, y); }
    [[nodiscard]] const T* at(int x, int y) const { return pixels.data() + index(x, y); }
};

using Rgb8Image = RgbImage<std::uint8_t>;
using RgbFloatImage = RgbImage<float>;

}  // namespace mogao
