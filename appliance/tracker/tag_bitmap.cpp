// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/tag_bitmap.h"

#include <apriltag.h>

#include <stdexcept>
#include <string>

namespace mogao {

TagBitmap make_tag_bitmap(const TagFamily& family, int id) {
    if (id < 0 || id >= family.code_count()) {
        throw std::invalid_argument("tag id " + std::to_string(id) + " outside [0, " +
                                    std::to_string(family.code_count()) + ") of family " + family.name());
    }
    const apriltag_family_t& f = *family.get();
    TagBitmap bitmap;
    bitmap.cells = f.total_width;
    bitmap.border_cells = f.width_at_border;
    bitmap.pixels.assign(static_cast<std::size_t>(f.total_width * f.total_width), 0);
    auto set = [&](int x, int y, std::uint8_t v) {
        if (x >= 0 && y >= 0 && x < f.total_width && y < f.total_width) {
            bitmap.pixels[static_cast<std::size_t>(y * f.total_width + x)] = v;
        }
    };
    const int b = (f.total_width - f.width_at_border) / 2;
    // Rings: classic families have a white ring just outside the black border ring; "reversed"
    // ones (tagStandard*, tagCircle*) have a white border ring with black outside it.
    const auto ring = [&](int start, int side, std::uint8_t v) {
        for (int i = 0; i < side; ++i) {
            set(start + i, start, v);
            set(start + i, start + side - 1, v);
            set(start, start + i, v);
            set(start + side - 1, start + i, v);
        }
    };
    if (f.reversed_border) {
        ring(b, f.width_at_border, 255);
    } else {
        ring(b - 1, f.width_at_border + 2, 255);
    }
    const std::uint64_t code = f.codes[id];
    for (std::uint32_t i = 0; i < f.nbits; ++i) {
        if ((code >> (f.nbits - 1 - i)) & 1U) {
            set(static_cast<int>(f.bit_x[i]) + b, static_cast<int>(f.bit_y[i]) + b, 255);
        }
    }
    return bitmap;
}

}  // namespace mogao
