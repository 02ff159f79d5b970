// SPDX-License-Identifier: Apache-2.0
// The One Euro filter (Casiez, Roussel, Vogel, "1 Euro Filter: A Simple Speed-based Low-pass
// Filter for Noisy Input in Interactive Systems", CHI 2012): a first-order low-pass whose cutoff
// rises with the signal's speed, so a still hand gives a still view (low cutoff, little jitter)
// and a fast turn is followed closely (high cutoff, little lag).
//
// Per sample x_i at time t_i (dt = t_i - t_{i-1}, seconds), from the paper:
//   alpha(fc)  = 1 / (1 + tau / dt),  tau = 1 / (2 pi fc)
//   dx_i       = (x_i - x^_{i-1}) / dt,      dx^_i = dx^_{i-1} + alpha(d_cutoff) (dx_i - dx^_{i-1})
//   fc         = min_cutoff + beta |dx^_i|
//   x^_i       = x^_{i-1} + alpha(fc) (x_i - x^_{i-1})
// The first sample passes unchanged (dx^ = 0). Parameters, in the units of the signal:
//   min_cutoff_hz  cutoff at rest: lower = less jitter, more lag when starting to move
//   beta           cutoff increase per unit of speed (Hz per signal-unit/s): higher = less lag
//                  when moving fast
//   d_cutoff_hz    cutoff of the speed estimate (the paper uses 1 Hz)
// mogao's values for the tag's angles and distances are in navigator.h (tuned by
// navigation_bench; docs/tracking.md).
#pragma once

namespace mogao {

struct OneEuroParams {
    double min_cutoff_hz = 1.0;  // > 0
    double beta = 0.0;           // >= 0
    double d_cutoff_hz = 1.0;    // > 0
};

// alpha of a first-order low-pass with cutoff fc (Hz) sampled after dt (s): 1 / (1 + 1/(2 pi fc dt)).
[[nodiscard]] double smoothing_factor(double cutoff_hz, double dt_s);

class OneEuroFilter {
public:
    // Throws std::invalid_argument naming the parameter and its limit.
    explicit OneEuroFilter(const OneEuroParams& params);

    // Filters x sampled at t_s (seconds, any origin). A sample not later than the previous one
    // leaves the state unchanged and returns the current value, and so does a NaN or infinite x or
    // t_s (0 before the first sample). Outputs stay within the range of the accepted samples at
    // any dt > 0 (alpha in (0, 1]); filter_time_step_test.cpp checks dt = 0, 1 us and 1 s.
    double filter(double x, double t_s);

    void reset() { initialized_ = false; }
    [[nodiscard]] bool initialized() const { return initialized_; }
    [[nodiscard]] double value() const { return x_; }
    [[nodiscard]] const OneEuroParams& params() const { return params_; }

private:
    OneEuroParams params_;
    bool initialized_ = false;
    double x_ = 0.0;   // x^
    double dx_ = 0.0;  // dx^
    double t_ = 0.0;
};

}  // namespace mogao
