// SPDX-License-Identifier: Apache-2.0
// The sRGB transfer functions (IEC 61966-2-1:1999, the piecewise definition): encoded values
// (0..1, gamma-encoded R'G'B') to linear light (0..1) and back, and the decoding of every 8-bit
// code, computed in double once. Pure functions; no errors (inputs outside [0, 1] follow the same
// formulas).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace mogao {

[[nodiscard]] inline double srgb_decode(double encoded) {
    return encoded <= 0.04045 ? encoded / 12.92 : std::pow((encoded + 0.055) / 1.055, 2.4);
}

[[nodiscard]] inline double srgb_encode(double linear) {
    return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

// Linear light -> the nearest 8-bit code (srgb_encode, rounded); outside [0, 1] clamps, NaN gives 0.
[[nodiscard]] inline std::uint8_t srgb8_encode(double linear) {
    const double x = linear > 0.0 ? std::min(linear, 1.0) : 0.0;
    return static_cast<std::uint8_t>(std::lround(255.0 * srgb_encode(x)));
}

// Linear light of each 8-bit code c (srgb_decode(c / 255)): what a GL_SRGB8 texel decodes to,
// without an implementation's approximation.
[[nodiscard]] inline const std::array<float, 256>& srgb8_decode_table() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (std::size_t c = 0; c < t.size(); ++c)
            t[c] = static_cast<float>(srgb_decode(static_cast<double>(c) / 255.0));
        return t;
    }();
    return table;
}

}  // namespace mogao
