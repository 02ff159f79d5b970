// SPDX-License-Identifier: Apache-2.0
// Several floats as one value (GCC and Clang vector extensions), for the denoiser's tap loops: a
// kernel written with these keeps a chunk of pixels' sums and centre values in registers while it
// walks their taps. Two widths, one per build of a kernel (common/cpu_level.h): eight floats (F8,
// one AVX register) for the x86-64-v3 build, four (F4, one SSE register) for the baseline build,
// whose sixteen SSE registers would not hold the chunk's values at eight. No intrinsics, so the same
// source builds anywhere. Internal to renderfarm/denoise.
//
// These helpers are always inlined, so the calling convention of a 32-byte vector (which differs
// with and without AVX, what GCC's -Wpsabi notes) is never used: a file that includes this header
// is built with -Wno-psabi (renderfarm/denoise/CMakeLists.txt).
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>

#include "common/cpu_level.h"

namespace mogao::lanes {

typedef float F8 __attribute__((vector_size(32)));
typedef std::int32_t I8 __attribute__((vector_size(32)));
typedef float F4 __attribute__((vector_size(16)));
typedef std::int32_t I4 __attribute__((vector_size(16)));

// The lane count of a float vector type, and its integer (mask) type.
template <typename F>
inline constexpr int kWidth = sizeof(F) / sizeof(float);
template <typename F>
struct MaskOf;
template <>
struct MaskOf<F8> {
    using type = I8;
};
template <>
struct MaskOf<F4> {
    using type = I4;
};
template <typename F>
using Mask = typename MaskOf<F>::type;

// Unaligned load and store of consecutive floats.
template <typename F>
MOGAO_ALWAYS_INLINE inline F load(const float* p) {
    F v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
template <typename F>
MOGAO_ALWAYS_INLINE inline void store(float* p, F v) {
    std::memcpy(p, &v, sizeof v);
}

template <typename F>
MOGAO_ALWAYS_INLINE inline F splat(float x) {
    return F{} + x;
}

// Lanes where `mask` is all ones take a, the others b (masks are what the comparisons return).
template <typename F>
MOGAO_ALWAYS_INLINE inline F select(Mask<F> mask, F a, F b) {
    return std::bit_cast<F>((std::bit_cast<Mask<F>>(a) & mask) | (std::bit_cast<Mask<F>>(b) & ~mask));
}

template <typename F>
MOGAO_ALWAYS_INLINE inline F abs(F v) {
    return std::bit_cast<F>(std::bit_cast<Mask<F>>(v) & 0x7fffffff);
}

// exp(-x) for x in [0, 40] lane by lane (callers clamp): 2^y, y = -x log2(e), split into the integer
// part t = trunc(y) (the float's exponent field) and f = y - t in (-1, 0] (degree-5 Taylor series of
// 2^f, relative error < 2e-4 — ample for filter weights, which are renormalised). Branch-free.
template <typename F>
MOGAO_ALWAYS_INLINE inline F exp_neg(F x) {
    const F y = -x * 1.44269504f;
    const Mask<F> whole = __builtin_convertvector(y, Mask<F>);  // truncates toward zero, as static_cast<int>
    const F f = y - __builtin_convertvector(whole, F);
    const F p = 1.0f + f * (0.69314718f + f * (0.24022651f + f * (0.05550411f + f * (0.00961813f + f * 0.00133336f))));
    return p * std::bit_cast<F>((whole + 127) << 23);
}

}  // namespace mogao::lanes
