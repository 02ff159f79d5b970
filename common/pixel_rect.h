// SPDX-License-Identifier: Apache-2.0
// Integer pixel rectangles and image sizes shared by every farm stage.
//
// Pixel convention: pixel (x, y) covers [x, x+1) x [y, y+1) in image coordinates; its centre is at
// (x + 0.5, y + 0.5). x grows to the right, y grows downward, (0, 0) is the top-left pixel.
#pragma once

#include <algorithm>
#include <cstdint>

namespace mogao {

struct ImageSize {
    int width = 0;   // pixels
    int height = 0;  // pixels
    [[nodiscard]] std::int64_t pixel_count() const { return std::int64_t{width} * height; }
    friend bool operator==(const ImageSize&, const ImageSize&) = default;
};

// Half-open rectangle [x0, x1) x [y0, y1) in pixels. Empty when x1 <= x0 or y1 <= y0.
struct PixelRect {
    int x0 = 0;
    int y0 = 0;
    int x1 = 0;
    int y1 = 0;

    [[nodiscard]] int width() const { return std::max(0, x1 - x0); }
    [[nodiscard]] int height() const { return std::max(0, y1 - y0); }
    [[nodiscard]] std::int64_t area() const { return std::int64_t{width()} * height(); }
    [[nodiscard]] bool empty() const { return width() == 0 || height() == 0; }
    [[nodiscard]] bool contains(int x, int y) const { return x >= x0 && x < x1 && y >= y0 && y < y1; }
    [[nodiscard]] static PixelRect whole(ImageSize s) { return {0, 0, s.width, s.height}; }
    friend bool operator==(const PixelRect&, const PixelRect&) = default;
};

[[nodiscard]] inline PixelRect intersect(const PixelRect& a, const PixelRect& b) {
    return {std::max(a.x0, b.x0), std::max(a.y0, b.y0), std::min(a.x1, b.x1), std::min(a.y1, b.y1)};
}

}  // namespace mogao
