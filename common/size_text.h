// SPDX-License-Identifier: Apache-2.0
// A size's text, "WIDTHxHEIGHT": the one parser of it (command lines, kiosk.toml). Also a pair of counts written
// the same way, such as a chessboard's inner corners "COLUMNSxROWS".
#pragma once

#include <charconv>
#include <string_view>

#include "common/pixel_rect.h"

namespace mogao {

// "WIDTHxHEIGHT" (decimal digits only, at most 6 per side, a lower-case x) -> true and `out` set; false and `out`
// untouched otherwise. Each caller checks its own range and names its flag or key in its message.
[[nodiscard]] inline bool parse_size(std::string_view text, ImageSize& out) {
    const auto x = text.find('x');
    if (x == std::string_view::npos || x == 0 || x + 1 >= text.size()) return false;
    const auto parse = [](std::string_view digits, int& value) {
        if (digits.empty() || digits.size() > 6) return false;
        for (const char c : digits) {
            if (c < '0' || c > '9') return false;
        }
        const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
        return ec == std::errc() && end == digits.data() + digits.size();
    };
    ImageSize s;
    if (!parse(text.substr(0, x), s.width) || !parse(text.substr(x + 1), s.height)) return false;
    out = s;
    return true;
}

// parse_size with each side in [lo, hi].
[[nodiscard]] inline bool parse_size(std::string_view text, ImageSize& out, int lo, int hi) {
    ImageSize s;
    if (!parse_size(text, s) || s.width < lo || s.height < lo || s.width > hi || s.height > hi) return false;
    out = s;
    return true;
}

}  // namespace mogao
