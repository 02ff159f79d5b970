// SPDX-License-Identifier: Apache-2.0
// Kernels compiled twice: for the x86-64 baseline every build targets (SSE2) and for x86-64-v3
// (AVX2, FMA, BMI2: Haswell and Zen onwards), chosen at run time on the CPU that runs them. A hot loop
// that vectorises runs on eight floats instead of four, with fused multiply-adds.
//
// How to use: write the loop once as an always-inline body, then two wrappers:
//
//     MOGAO_ALWAYS_INLINE inline void filter_body(...) { ... }
//     MOGAO_TARGET_X86_64_V3 void filter_v3(...) { filter_body(...); }
//     void filter_base(...) { filter_body(...); }
//
// and call filter_v3 only where use_x86_64_v3(...) says so. The body is compiled into each wrapper
// with that wrapper's instruction set; nothing else in the program is (unlike a whole file built with
// -march=x86-64-v3, whose inline functions could be shared with baseline code by the linker).
//
// Results of the two builds may differ in the last bits of a float: FMA rounds once where a multiply
// and an add round twice. Elsewhere than x86-64 with GCC (Clang: the fuzzing build), or under a
// sanitizer, only the baseline build exists (MOGAO_HAS_X86_64_V3 is 0) and use_x86_64_v3 is false.
#pragma once

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__) && \
    !defined(__SANITIZE_THREAD__)
#define MOGAO_HAS_X86_64_V3 1
#define MOGAO_TARGET_X86_64_V3 __attribute__((target("arch=x86-64-v3")))
#else
#define MOGAO_HAS_X86_64_V3 0
#define MOGAO_TARGET_X86_64_V3
#endif
#define MOGAO_ALWAYS_INLINE [[gnu::always_inline]]

namespace mogao {

// Which build of a kernel to run: the best this CPU runs (automatic), or the baseline build on any
// CPU (to compare the two in tests and benchmarks).
enum class CpuLevel { automatic, baseline };

// Whether this CPU has every feature of x86-64-v3 (AVX, AVX2, BMI1, BMI2, F16C, FMA, LZCNT, MOVBE,
// XSAVE; the operating system saving the AVX registers), read once.
[[nodiscard]] bool cpu_has_x86_64_v3();

// Whether to run the x86-64-v3 build of a kernel: it exists, `level` allows it and the CPU has it.
[[nodiscard]] inline bool use_x86_64_v3(CpuLevel level) {
    return MOGAO_HAS_X86_64_V3 && level == CpuLevel::automatic && cpu_has_x86_64_v3();
}

}  // namespace mogao
