// SPDX-License-Identifier: Apache-2.0
// Edge-avoiding à-trous wavelet filter for low-spp frames, guided by albedo, normal and depth.
//
// Sources:
//   [D] H. Dammertz, D. Sewtz, J. Hanika, H. Lensch, "Edge-Avoiding À-Trous Wavelet Transform for
//       fast Global Illumination Filtering", HPG 2010: the filter structure (iterated 5x5 B3-spline
//       kernel h = (1/16, 1/4, 3/8, 1/4, 1/16) ⊗ h with holes, step 2^i at iteration i) and the
//       edge-stopping Gaussian on normals, w_n = exp(-|n_p - n_q|² / σ_n²).
//   [S] C. Schied et al., "Spatiotemporal Variance-Guided Filtering", HPG 2017 (the spatial part):
//       demodulation by albedo before filtering and re-modulation after (§4.1, so texture is not
//       blurred), the luminance weight normalised by the local noise (eq. 5)
//           w_l = exp(-|l_p - l_q| / (σ_l sqrt(g3x3(Var(l_p))) + ε)),
//       the depth weight scaled by the screen-space depth gradient (eq. 3)
//           w_z = exp(-|z_p - z_q| / (σ_z |∇z_p · (p - q)| + ε_z)),
//       and the variance filtered alongside the signal, Var' = Σ w² Var / (Σ w)² (eq. 2, end of §4.2).
//       Without temporal history the per-pixel luminance variance is estimated spatially (§4.2:
//       the 7x7 bilateral estimate for short histories; here 5x5, weighted by normal and depth).
// Each tap weighs h(dx) h(dy) w_l w_n w_z; the weights are not separable, so every iteration is a
// 25-tap sparse kernel (the three factors share one exp).
//
// Conventions:
//   noisy   linear RGB radiance (RgbFloatImage, common/image.h: row-major, top row first, pixel
//           (x, y) centred at (x + 0.5, y + 0.5)), any non-negative scale. NaN/inf samples are
//           treated as 0 (a firefly must not poison its neighbours).
//   guides  GuideBuffers of the same size (guide_buffers.h). Sky pixels (hit 0) are copied through
//           unchanged (NaN/inf as 0) and never mix with surface pixels in either direction.
//   l       luminance of the demodulated colour, Rec. 709 weights (0.2126, 0.7152, 0.0722).
//   Demodulation divides each channel by max(albedo, 1e-3) and re-modulation multiplies by
//   the same value, so a pixel that no neighbour may touch is returned unchanged (to float rounding).
// Parameters (AtrousParams): every σ is a tolerance; 0 = only exactly equal values may mix (with
// σ_colour = 0 the output equals the input); larger = more smoothing. iterations = 0 returns the input.
//
// Errors (Result / Status, common/result.h, code EINVAL): an empty image, a pixel buffer whose
// length is not W·H·3, guides of another size or with buffers of the wrong length, iterations
// outside [0, kMaxIterations], a σ that is negative or not finite, threads < 0, a hit pixel whose
// depth is not finite and > 0. The message names the field and the limit; `out` is not touched.
// Cost: (25 + 25 · iterations) taps per surface pixel, each one exp (the first 25 only where the
// luminance variance is not given); threads split rows. The tap loops
// run eight pixels at a time where the CPU has x86-64-v3 (AVX2, FMA), else four.
#pragma once

#include <vector>

#include "common/cpu_level.h"
#include "common/image.h"
#include "common/result.h"
#include "renderfarm/trace/guide_buffers.h"

namespace mogao {

// Demodulation divides each channel by max(albedo, this) (see above); the temporal accumulation
// (temporal_accumulation.h) demodulates the same way.
inline constexpr float kDemodulationMinAlbedo = 1e-3f;

struct AtrousParams {
    static constexpr int kMaxIterations = 10;  // step 2^9 = 512 px at the last one
    int iterations = 3;         // à-trous levels, steps 1, 2, 4 px: on the grotto at 1 spp as close to the
                                // reference as 4 or 5 levels, for less time (mogao_bench_denoise --iterations)
    float sigma_colour = 4.0f;  // σ_l [S]: in standard deviations of the local luminance noise
    float sigma_normal = 0.5f;  // σ_n [D]: on |n_p - n_q| (unit normals: 0.5 ≈ weight 1/e at 29°)
    float sigma_depth = 1.0f;   // σ_z [S]: in multiples of the depth change the local slope predicts
    int threads = 1;            // row bands run on this many threads; 0 = std::thread::hardware_concurrency
    // The kernels' build (common/cpu_level.h): x86-64-v3 where the CPU has it, or the baseline build
    // (tests and benchmarks compare the two; results agree to float rounding, not bit for bit).
    CpuLevel cpu = CpuLevel::automatic;
};

// Reusable scratch buffers: keep one AtrousDenoiser per stream of frames so that per-frame calls
// allocate nothing once the size is stable. Not thread-safe (one frame at a time per object).
class AtrousDenoiser {
public:
    // Filters `noisy` into `out` (resized to noisy.size). On error, `out` is left untouched.
    // `variance`, when given: the measured variance of each pixel of `noisy`, per channel (W*H*3,
    // squared radiance units, finite and >= 0; e.g. ProgressiveAccumulator::variance_of_mean). The
    // luminance weight w_l is then normalised by that noise instead of the spatial estimate (the
    // luminance variance of the demodulated colour, channels taken as fully correlated, averaged
    // over the 5x5 neighbourhood on the same surface): as samples accumulate and the noise falls,
    // the filter lets less through and its output tends to `noisy` itself, where the spatial
    // estimate, which also sees shading and texture, would keep blurring them.
    // EINVAL naming the field for a variance of another size or a negative or non-finite value.
    // `luminance_variance`, when given (not with `variance`): W*H values, the variance of each
    // pixel's demodulated luminance l (squared illumination units), e.g. SVGF's temporal estimate
    // (TemporalHistory::luminance_variance, temporal_accumulation.h); a negative value means unknown,
    // and that pixel gets the spatial estimate. It then drives w_l as the spatial estimate would
    // ([S] §4.2: the temporal variance where the history is long enough), and the 5x5 spatial pass
    // runs only for the chunks of pixels the tap loops take together (eight with AVX2, else four) that
    // hold an unknown one. EINVAL naming the field for another size, a non-finite
    // value, or both variances given.
    Status run(const RgbFloatImage& noisy, const GuideBuffers& guides, const AtrousParams& params, RgbFloatImage& out,
               const RgbFloatImage* variance = nullptr, const std::vector<float>* luminance_variance = nullptr);

private:
    // Planes of W*H floats, structure of arrays so the per-tap loops over a row vectorise:
    // two sets of (r, g, b, variance, luminance) for ping-pong, the geometry (normal x, y, z, depth,
    // depth slope x, y, surface mask) and the per-level colour scale. Layout in atrous_filter.cpp.
    std::vector<float> planes_;
};

// One-shot convenience: a fresh AtrousDenoiser, the filtered image or the error.
[[nodiscard]] Result<RgbFloatImage> denoise_atrous(const RgbFloatImage& noisy, const GuideBuffers& guides,
                                                   const AtrousParams& params = {});

// Checks sizes and parameters without filtering (the errors listed above).
[[nodiscard]] Status validate_denoise_input(const RgbFloatImage& noisy, const GuideBuffers& guides,
                                            const AtrousParams& params);

}  // namespace mogao
