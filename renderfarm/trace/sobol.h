// SPDX-License-Identifier: Apache-2.0
// Low-discrepancy pixel sampler: shuffled, Owen-scrambled 2D Sobol' points, padded per dimension
// pair (Burley, "Practical Hash-based Owen Scrambling", JCGT 9(4), 2020, §3-§4, with its hash
// constants; PBRT 4th ed. §8.7, ZSobolSampler/PaddedSobolSampler).
//
// Every pair of dimensions (pixel jitter, each light or environment sample, each bounce
// direction) is its own 2D Sobol' (0,2)-sequence (dimensions 0 and 1 of Sobol' 1967: the
// van der Corput radical inverse and the Pascal-matrix dimension), whose point index is shuffled
// and whose coordinates are Owen-scrambled by nested uniform scrambling with seeds hashed from
// (frame key, pixel, dimension pair). Consequences:
//   * the first 2^m points of any pair in a pixel form a (0,m,2)-net: every elementary interval
//     of area 2^-m ([a/2^i, (a+1)/2^i) x [b/2^(m-i), (b+1)/2^(m-i))) holds exactly one point,
//     for any spp, with no empty cells when spp is not a rectangle count (3, 5, 7, ...): a
//     prefix of a net is still spread over the square;
//   * a pair used `count` times per pixel sample (e.g. ao_samples rays per vertex) takes points
//     sample * count + k, so all spp * count points of the pixel are one net;
//   * different pairs and pixels are decorrelated by their hashed seeds (padding), so no
//     structure leaks between dimensions; values are pure functions of (key, x, y, sample,
//     pair), as the renderer's determinism needs.
// Values are uniform on [0, 1) with step 2^-24.
#pragma once

#include <array>
#include <cstdint>

#include <Eigen/Core>

#include "renderfarm/trace/rng.h"

namespace mogao {

[[nodiscard]] constexpr std::uint32_t reverse_bits32(std::uint32_t x) {
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0F0F0F0Fu) | ((x & 0x0F0F0F0Fu) << 4);
    x = ((x >> 8) & 0x00FF00FFu) | ((x & 0x00FF00FFu) << 8);
    return (x >> 16) | (x << 16);
}

// Burley 2020, listing 2 (improved Laine-Karras hash): bit i of the result depends only on bits
// <= i of x, so applied to reversed bits it is a nested uniform (Owen) scramble.
[[nodiscard]] constexpr std::uint32_t laine_karras_permutation(std::uint32_t x, std::uint32_t seed) {
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

[[nodiscard]] constexpr std::uint32_t nested_uniform_scramble(std::uint32_t x, std::uint32_t seed) {
    return reverse_bits32(laine_karras_permutation(reverse_bits32(x), seed));
}

// Sobol' dimension 1 (0-based): direction numbers v_0 = 2^31, v_k = v_(k-1) ^ (v_(k-1) >> 1); bit by bit.
[[nodiscard]] constexpr std::uint32_t sobol_dimension1_bitwise(std::uint32_t index) {
    std::uint32_t v = 0x80000000u;
    std::uint32_t result = 0;
    for (; index != 0; index >>= 1, v ^= v >> 1) {
        if ((index & 1u) != 0) result ^= v;
    }
    return result;
}

namespace detail {
// The generator matrix is linear over GF(2): the image of an index is the XOR of the images of its
// four bytes, each looked up in a 256-entry table (shuffled indices use all 32 bits, so the bitwise
// loop would run about 32 times per point).
struct SobolDimension1Bytes {
    std::array<std::array<std::uint32_t, 256>, 4> table{};
    constexpr SobolDimension1Bytes() {
        for (std::uint32_t k = 0; k < 4; ++k)
            for (std::uint32_t b = 0; b < 256; ++b) table[k][b] = sobol_dimension1_bitwise(b << (8 * k));
    }
};
inline constexpr SobolDimension1Bytes kSobolDimension1Bytes{};
}  // namespace detail

// The same values as sobol_dimension1_bitwise (tested), four table lookups.
[[nodiscard]] constexpr std::uint32_t sobol_dimension1(std::uint32_t index) {
    const auto& t = detail::kSobolDimension1Bytes.table;
    return t[0][index & 0xFFu] ^ t[1][(index >> 8) & 0xFFu] ^ t[2][(index >> 16) & 0xFFu] ^ t[3][index >> 24];
}

// The 2D point `index` of the scrambled, shuffled sequence with the given seed.
[[nodiscard]] inline Eigen::Vector2f owen_sobol_2d(std::uint32_t index, std::uint64_t seed) {
    const std::uint64_t h = mix64(seed);
    const std::uint32_t shuffled = nested_uniform_scramble(index, static_cast<std::uint32_t>(h));
    // nested_uniform_scramble(reverse_bits32(shuffled), s) with its two inner reversals cancelled.
    const std::uint32_t x = reverse_bits32(laine_karras_permutation(shuffled, static_cast<std::uint32_t>(h >> 32)));
    const std::uint32_t y = nested_uniform_scramble(sobol_dimension1(shuffled), static_cast<std::uint32_t>(mix64(h)));
    return {static_cast<float>(x >> 8) * 0x1p-24f, static_cast<float>(y >> 8) * 0x1p-24f};
}

// The sampler of one pixel sample. Each take() consumes one dimension pair.
class PixelSampler {
public:
    // One dimension pair: point(k, count) is point k of `count` drawn for this pixel sample.
    struct Pair {
        std::uint64_t seed = 0;
        std::uint32_t sample = 0;
        [[nodiscard]] Eigen::Vector2f point(int k = 0, int count = 1) const {
            return owen_sobol_2d(sample * static_cast<std::uint32_t>(count) + static_cast<std::uint32_t>(k), seed);
        }
    };

    PixelSampler() = default;  // key 0; only meant to be assigned over
    PixelSampler(std::uint64_t frame, int x, int y, int sample)
        : pixel_(mix64(frame ^ mix64((static_cast<std::uint64_t>(static_cast<std::uint32_t>(x)) << 32) |
                                     static_cast<std::uint32_t>(y)))),
          sample_(static_cast<std::uint32_t>(sample)) {}

    [[nodiscard]] Pair take() { return Pair{pixel_ + 0x9e3779b97f4a7c15ULL * ++pair_, sample_}; }
    [[nodiscard]] Eigen::Vector2f next2d() { return take().point(); }
    [[nodiscard]] std::uint64_t pairs_taken() const { return pair_; }

private:
    std::uint64_t pixel_ = 0;
    std::uint32_t sample_ = 0;
    std::uint64_t pair_ = 0;
};

}  // namespace mogao
