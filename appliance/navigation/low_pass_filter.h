// SPDX-License-Identifier: Apache-2.0
// A plain first-order low-pass (exponential smoothing with a fixed cutoff), time-aware:
// y_i = y_{i-1} + alpha (x_i - y_{i-1}), alpha = smoothing_factor(cutoff_hz, dt) (one_euro_filter.h).
// The baseline the One Euro filter is compared with in navigation_bench.
#pragma once

namespace mogao {

class LowPassFilter {
public:
    // Throws std::invalid_argument unless cutoff_hz is finite and > 0.
    explicit LowPassFilter(double cutoff_hz);

    // First sample passes unchanged; a sample not later than the previous one changes nothing, nor
    // does a NaN or infinite x or t_s (returns the current value, 0 before the first sample).
    double filter(double x, double t_s);
    void reset() { initialized_ = false; }
    [[nodiscard]] double value() const { return y_; }

private:
    double cutoff_hz_;
    bool initialized_ = false;
    double y_ = 0.0;
    double t_ = 0.0;
};

}  // namespace mogao
