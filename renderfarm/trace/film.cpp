// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/trace/film.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

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

// encode_srgb8 with its tables looked up once (to_srgb8 encodes every channel of a frame).
class SrgbEncoder {
public:
    SrgbEncoder() : table_(table()), thresholds_(code_thresholds()) {}
    [[nodiscard]] std::uint8_t operator()(float linear) const {
        // NaN fails the comparison and ends at 0; +inf clamps to 1.
        const float v = linear > 0.0f ? std::min(linear, 1.0f) : 0.0f;
        std::uint8_t code = table_.code[std::bit_cast<std::uint32_t>(v) >> kShift];
        while (code < 255 && static_cast<double>(v) >= thresholds_[code]) ++code;
        return code;
    }

private:
    static const SrgbTable& table() {
        static const SrgbTable t;
        return t;
    }
    const SrgbTable& table_;
    const std::array<double, 255>& thresholds_;
};

// Rows [y0, y1) of rect.
void to_srgb8_rows(const RgbFloatImage& in, const PixelRect& rect, int y0, int y1, float exposure, Rgb8Image& out,
                   ToneMap op) {
    const SrgbEncoder encode;
    for (int y = y0; y < y1; ++y) {
        const float* src = in.at(rect.x0, y);
        std::uint8_t* dst = out.at(rect.x0, y);
        for (int i = 0; i < 3 * (rect.x1 - rect.x0); ++i) {
            const float v = exposure * src[i];
            // NaN fails the comparison and stays NaN -> code 0; +inf -> 1 for every operator.
            dst[i] = encode(op == ToneMap::clamp || !(v > 0.0f) ? v : (std::isinf(v) ? 1.0f : tone_map(op, v)));
        }
    }
}

}  // namespace

std::uint8_t encode_srgb8(float linear) {
    static const SrgbEncoder encode;
    return encode(linear);
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

void to_srgb8(const RgbFloatImage& in, const PixelRect& rect, float exposure, Rgb8Image& out, ToneMap op, int threads) {
    if (!(in.size == out.size)) throw std::invalid_argument("to_srgb8: input and output sizes differ");
    if (rect.x0 < 0 || rect.y0 < 0 || rect.x1 > in.size.width || rect.y1 > in.size.height) {
        throw std::invalid_argument("to_srgb8: rect is outside the image");
    }
    if (!(exposure >= 0.0f) || !std::isfinite(exposure)) {
        throw std::invalid_argument("to_srgb8: exposure must be finite and >= 0");
    }
    if (threads < 0) throw std::invalid_argument("to_srgb8: threads must be >= 0, is " + std::to_string(threads));
    if (rect.empty()) return;
    const int rows = rect.y1 - rect.y0;
    if (threads == 0) threads = static_cast<int>(std::thread::hardware_concurrency());
    threads = std::clamp(threads, 1, std::max(1, rows / 16));  // a band of at least 16 rows
    std::vector<std::thread> workers;
    for (int t = 1; t < threads; ++t) {
        workers.emplace_back([&, t] {
            to_srgb8_rows(in, rect, rect.y0 + rows * t / threads, rect.y0 + rows * (t + 1) / threads, exposure, out,
                          op);
        });
    }
    to_srgb8_rows(in, rect, rect.y0, rect.y0 + rows / threads, exposure, out, op);
    for (std::thread& w : workers) w.join();
}

}  // namespace mogao
