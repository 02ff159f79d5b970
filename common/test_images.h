// SPDX-License-Identifier: Apache-2.0
// Synthetic images shared by the encode tests and the quality benchmark.
#pragma once

#include <algorithm>
#include <cstdint>

#include "common/image.h"

namespace mogao::test_images {

// Smooth diagonal colour gradient: the easy case for JPEG (almost all energy in DC/low AC).
inline Rgb8Image gradient(ImageSize size) {
    Rgb8Image img(size);
    for (int y = 0; y < size.height; ++y) {
        for (int x = 0; x < size.width; ++x) {
            std::uint8_t* p = img.at(x, y);
            p[0] = static_cast<std::uint8_t>(255 * x / std::max(1, size.width - 1));
            p[1] = static_cast<std::uint8_t>(255 * y / std::max(1, size.height - 1));
            p[2] = static_cast<std::uint8_t>(255 * (x + y) / std::max(1, size.width + size.height - 2));
        }
    }
    return img;
}

// Every value 0..255 in every channel, no structure: exercises lossless round trips.
inline Rgb8Image noise(ImageSize size, std::uint32_t seed = 12345) {
    Rgb8Image img(size);
    std::uint32_t state = seed;
    for (std::uint8_t& v : img.pixels) {
        state = state * 1664525u + 1013904223u;  // LCG: deterministic on every platform
        v = static_cast<std::uint8_t>(state >> 24);
    }
    return img;
}

}  // namespace mogao::test_images
