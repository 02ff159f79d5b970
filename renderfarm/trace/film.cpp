// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/trace/film.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#include "common/srgb.h"

namespace mogao {
namespace {

// thresholds[k] = smallest linear value whose code is k + 1, i.e. OETF⁻¹((k + 0.5) / 255): the
// code is the number of thresholds <= v. Same result as lround(255 * OETF(v)) without a pow per
// channel (a 1080p frame has 6 million channels).
const std::array<double, 255>& code_thresholds() {
    static const std::array<double, 255> thresholds = [] {
        std::array<double, 255> t{};
        for (std::size_t k = 0; k < t.size(); ++k) t[k] = srgb_decode((static_cast<double>(k) + 0.5) / 255.0);
        return t;
    }();
    return thresholds;
}

// Lookup table over the float bit pattern: floats in [0, 1] are the bit patterns 0..0x3F800000,
// monotonic in value; entry i holds the code of the smallest float of the bucket of 2^kShift
// consecutive patterns starting at i << kShift. A bucket spans a relative width of 2^-7 (the top
// 7 mantissa bits stay in the index), narrower than one code step (>= 0.9 % of the value above
// code 1), so the exact code is the entry plus the thresholds the value still passes: at most one
// comparison in practice, instead of a binary search over 255 thresholds per channel.
constexpr int kShift = 16;
constexpr std::uint32_t kOneBits = 0x3F800000u;

struct SrgbTable {
    std::array<std::uint8_t, (kOneBits >> kShift) + 1> code{};
    SrgbTable() {
        const auto& t = code_thresholds();
        for (std::size_t i = 0; i < code.size(); ++i) {
            const double v = std::bit_cast<float>(static_cast<std::uint32_t>(i << kShift));
            code[i] = static_cast<std::uint8_t>(std::upper_bound(t.begin(), t.end(), v) - t.begin());
        }
    }
};

}  // namespace

std::uint8_t encode_srgb8(float linear) {
    static const SrgbTable table;
    // NaN fails the comparison and ends at 0; +inf clamps to 1.
    const float v = linear > 0.0f ? std::min(linear, 1.0f) : 0.0f;
    const auto bits = std::bit_cast<std::uint32_t>(v);
    std::uint8_t code = table.code[bits >> kShift];
    const auto& t = code_thresholds();
    while (code < 255 && static_cast<double>(v) >= t[code]) ++code;
    return code;
}

float tone_map(ToneMap op, float x) {
    switch (op) {
        case ToneMap::clamp:
            return x;  // encode_srgb8 clamps
        case ToneMap::reinhard:
            return x / (1.0f + x);
        case ToneMap::aces:
            return (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f);
    }
    return x;
}

ToneMap parse_tone_map(const std::string& name) {
    if (name == "clamp") return ToneMap::clamp;
    if (name == "reinhard") return ToneMap::reinhard;
    if (name == "aces") return ToneMap::aces;
    throw std::invalid_argument("tone map '" + name + "' is not one of clamp, reinhard, aces");
}

const char* tone_map_name(ToneMap op) {
    switch (op) {
        case ToneMap::clamp:
            return "clamp";
        case ToneMap::reinhard:
            return "reinhard";
        case ToneMap::aces:
            return "aces";
    }
    return "?";
}

void to_srgb8(const RgbFloatImage& in, const PixelRect& rect, float exposure, Rgb8Image& out, ToneMap op) {
    if (!(in.size == out.size)) throw std::invalid_argument("to_srgb8: input and output sizes differ");
    if (rect.x0 < 0 || rect.y0 < 0 || rect.x1 > in.size.width || rect.y1 > in.size.height) {
        throw std::invalid_argument("to_srgb8: rect is outside the image");
    }
    if (!(exposure >= 0.0f) || !std::isfinite(exposure)) {
        throw std::invalid_argument("to_srgb8: exposure must be finite and >= 0");
    }
    for (int y = rect.y0; y < rect.y1; ++y) {
        for (int x = rect.x0; x < rect.x1; ++x) {
            const float* src = in.at(x, y);
            std::uint8_t* dst = out.at(x, y);
            for (int c = 0; c < 3; ++c) {
                const float v = exposure * src[c];
                // NaN fails the comparison and stays NaN -> code 0; +inf -> 1 for every operator.
                dst[c] =
                    encode_srgb8(op == ToneMap::clamp || !(v > 0.0f) ? v : (std::isinf(v) ? 1.0f : tone_map(op, v)));
            }
        }
    }
}

}  // namespace mogao
