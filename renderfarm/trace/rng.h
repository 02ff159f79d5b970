// SPDX-License-Identifier: Apache-2.0
// Counter-based random numbers: every value is a pure hash of (seed, frame_id, pixel x, y,
// sample index, dimension), so a pixel's samples never depend on which rect, thread or packet
// rendered it, nor on how many random numbers other pixels used.
//
// Hash: the splitmix64 output function (Steele, Lea, Flood, "Fast splittable pseudorandom number
// generators", OOPSLA 2014; constants of Stafford's "Mix13"), applied to keys combined with
// distinct odd multipliers. Floats use the top 24 bits: uniform on [0, 1) with step 2^-24.
#pragma once

#include <cstdint>

namespace mogao {

[[nodiscard]] constexpr std::uint64_t mix64(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

// Key of one frame: everything shared by all pixels of a request.
[[nodiscard]] constexpr std::uint64_t frame_key(std::uint64_t seed, std::uint64_t frame_id) {
    return mix64(mix64(seed + 0x9e3779b97f4a7c15ULL) ^ (frame_id * 0xd1b54a32d192ed03ULL));
}

// The stream of one pixel sample; next() advances the dimension.
class PixelRng {
public:
    constexpr PixelRng() = default;  // key 0; only meant to be assigned over
    constexpr PixelRng(std::uint64_t frame, int x, int y, int sample)
        : key_(mix64(
              frame ^
              mix64((static_cast<std::uint64_t>(static_cast<std::uint32_t>(x)) << 32) | static_cast<std::uint32_t>(y)) ^
              (static_cast<std::uint64_t>(static_cast<std::uint32_t>(sample)) * 0xaef17502108ef2d9ULL))) {}

    // Uniform in [0, 1).
    [[nodiscard]] constexpr float next() {
        const std::uint64_t h = mix64(key_ + 0x9e3779b97f4a7c15ULL * ++dimension_);
        return static_cast<float>(h >> 40) * 0x1p-24f;
    }

    [[nodiscard]] constexpr std::uint64_t dimension() const { return dimension_; }

private:
    std::uint64_t key_ = 0;
    std::uint64_t dimension_ = 0;
};

}  // namespace mogao
