// SPDX-License-Identifier: Apache-2.0
// Progressive refinement of a still view: successive passes of the same view are averaged, so the
// wall converges toward the exhibit-quality (many-spp) image while the visitor stands still.
//
// Each pass is a frame of linear radiance rendered with its own RNG key (pass_frame_id below), so
// its samples are new; the accumulator keeps the spp-weighted sum in linear float (never in sRGB8,
// whose rounding and non-linearity would bias the mean) and hands out the mean:
//     mean = sum_k (spp_k * pass_k) / sum_k spp_k
// which is the Monte Carlo estimate with all the passes' samples together. It also keeps the
// spp-weighted sum of squares of the passes, for the noise left in the mean (variance_of_mean()):
// a pass of n_k samples has Var(pass_k) = σ² / n_k, so with N = Σ n_k and P passes
//     σ² ≈ Σ_k n_k (pass_k - mean)² / (P - 1) = (Σ_k n_k pass_k² - N mean²) / (P - 1)
//     Var(mean) = σ² / N
// per pixel and channel (the pass-to-pass estimate of the "temporal" variance of Schied et al.,
// "Spatiotemporal Variance-Guided Filtering", HPG 2017, §4.2, with passes in place of frames).
// Any change of the view
// (same_view() below: pose, camera, size, resolution scale, bounces, AO, area samples, seed)
// starts over: the first pass of a new view replaces the sum.
//
// Shapes: every pass must have render_size(view) pixels (std::invalid_argument otherwise).
#pragma once

#include <cstdint>

#include "common/image.h"
#include "common/view_request.h"

namespace mogao {

// True when the two requests render the same image up to sampling noise: everything but frame_id,
// request_time_ns, session, spp and jpeg_quality is equal (exact comparison: a pose that moved by
// any amount is a new view).
[[nodiscard]] bool same_view(const ViewRequest& a, const ViewRequest& b);

// The frame_id the renderer is given for pass `pass` (0, 1, ...) of a still view first requested
// as `first_frame_id`: distinct for every pass, so no two passes reuse random numbers (rng.h keys
// them on seed and frame_id). Pass 0 keeps the request's own id (a single frame renders as today).
[[nodiscard]] std::uint64_t pass_frame_id(std::uint64_t first_frame_id, int pass);

class ProgressiveAccumulator {
public:
    // Adds one pass rendered for `view` with view.quality.spp samples per pixel. Starts over first
    // when `view` is not same_view() as the accumulated one. Returns the samples per pixel now in
    // the mean.
    int add(const ViewRequest& view, const RgbFloatImage& pass);

    [[nodiscard]] int samples() const { return samples_; }
    [[nodiscard]] int passes() const { return passes_; }
    // Whether the next pass of `view` would continue this accumulation (false when empty).
    [[nodiscard]] bool continues(const ViewRequest& view) const { return passes_ > 0 && same_view(view, view_); }
    [[nodiscard]] std::uint64_t first_frame_id() const { return view_.frame_id; }
    // The mean radiance of every pass so far (empty image before the first add()).
    [[nodiscard]] RgbFloatImage mean() const;
    // The variance of mean()'s pixels, per channel, in squared radiance units (formula above; >= 0,
    // rounding clamped). Empty before the second pass: one pass says nothing of its own noise.
    [[nodiscard]] RgbFloatImage variance_of_mean() const;
    void reset();

private:
    ViewRequest view_;
    RgbFloatImage sum_;          // spp-weighted sum of passes, linear
    RgbFloatImage sum_squares_;  // spp-weighted sum of the passes' squares
    int samples_ = 0;
    int passes_ = 0;
};

}  // namespace mogao
