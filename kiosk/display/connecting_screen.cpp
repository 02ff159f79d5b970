// SPDX-License-Identifier: Apache-2.0
#include "kiosk/display/connecting_screen.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "kiosk/display/bitmap_font.h"

namespace mogao {
namespace {

constexpr int kMaxSide = 16384;

void set(Rgb8Image& image, int x, int y, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
    std::uint8_t* p = image.at(x, y);
    p[0] = r;
    p[1] = g;
    p[2] = b;
}

// Largest integer scale at which `text` fits in `width` pixels (at least 1).
int fit_scale(std::string_view text, int width, int preferred) {
    int scale = std::max(1, preferred);
    while (scale > 1 && text_width(text, scale) > width) --scale;
    return scale;
}

}  // namespace

Rgb8Image make_connecting_screen(ImageSize content, std::string_view detail) {
    return make_title_card(content, "CONNECTING", detail);
}

Rgb8Image make_title_card(ImageSize content, std::string_view title, std::string_view detail) {
    if (content.width < 1 || content.width > kMaxSide || content.height < 1 || content.height > kMaxSide) {
        throw std::invalid_argument("make_title_card: content size " + std::to_string(content.width) + "x" +
                                    std::to_string(content.height) + " is outside [1, 16384] per side");
    }
    const int w = content.width;
    const int h = content.height;
    Rgb8Image image(content);
    // Dim gradient, top (20, 26, 40) to bottom (38, 46, 64).
    for (int y = 0; y < h; ++y) {
        const double t = h > 1 ? static_cast<double>(y) / (h - 1) : 0.0;
        const auto r = static_cast<std::uint8_t>(20 + 18 * t);
        const auto g = static_cast<std::uint8_t>(26 + 20 * t);
        const auto b = static_cast<std::uint8_t>(40 + 24 * t);
        for (int x = 0; x < w; ++x) set(image, x, y, r, g, b);
    }
    // Grid every 1/24 of the width (square cells), lines one pixel wide.
    const int cell = std::max(2, w / 24);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            if (x % cell == 0 || y % cell == 0) set(image, x, y, 52, 62, 86);
        }
    }
    // Frame around the edge.
    const int border = std::max(1, std::min(w, h) / 100);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            if (x < border || y < border || x >= w - border || y >= h - border) set(image, x, y, 110, 116, 130);
        }
    }
    // The title across about half the width, centred; the detail line at a third of that size.
    const int title_scale = fit_scale(title, w - 2 * border, w / 2 / (static_cast<int>(title.size()) * kGlyphAdvance));
    const int title_h = kGlyphHeight * title_scale;
    const int detail_scale = fit_scale(detail, w - 2 * border, std::max(1, title_scale / 3));
    const int detail_h = detail.empty() ? 0 : kGlyphHeight * detail_scale;
    const int gap = detail.empty() ? 0 : std::max(2, title_h / 2);
    const int top = (h - (title_h + gap + detail_h)) / 2;
    draw_text(image, (w - text_width(title, title_scale)) / 2, top, title_scale, title, {220, 220, 228});
    if (!detail.empty()) {
        draw_text(image, (w - text_width(detail, detail_scale)) / 2, top + title_h + gap, detail_scale, detail,
                  {150, 156, 176});
    }
    return image;
}

}  // namespace mogao
