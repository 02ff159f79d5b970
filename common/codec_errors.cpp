// SPDX-License-Identifier: Apache-2.0
#include "common/codec_errors.h"

#include <string>

namespace mogao {

void require_valid_image(const Rgb8Image& image, std::string_view who) {
    const ImageSize s = image.size;
    if (s.width <= 0 || s.height <= 0) {
        throw std::invalid_argument(std::string(who) + ": image is empty (" + std::to_string(s.width) + "x" +
                                    std::to_string(s.height) + ")");
    }
    // Compare in 64 bits: a corrupt size must not wrap around to match the vector.
    if (static_cast<std::uint64_t>(image.pixels.size()) != static_cast<std::uint64_t>(s.pixel_count()) * 3) {
        throw std::invalid_argument(std::string(who) + ": pixel buffer holds " + std::to_string(image.pixels.size()) +
                                    " values, " + std::to_string(s.width) + "x" + std::to_string(s.height) +
                                    " RGB8 needs " + std::to_string(s.pixel_count() * 3));
    }
}

}  // namespace mogao
