// SPDX-License-Identifier: Apache-2.0
// QuantileSketch: quantiles of a stream of positive values in fixed memory, with a bounded relative
// error -- DDSketch (Masson, Rim and Lee, "DDSketch: a fast and fully-mergeable quantile sketch with
// relative-error guarantees", VLDB 2019).
//
// Bucket i counts the values x with gamma^(i-1) < x <= gamma^i, gamma = (1 + a) / (1 - a) for the
// relative accuracy a; a quantile is answered by the bucket holding the value of that rank, as
// 2 gamma^i / (gamma + 1), which is within a * x of every x in the bucket. Values at or below 0
// are counted apart (answered as 0); values outside [min_value, max_value] are clamped into the end
// buckets (answered within the accuracy of the range's ends). Memory: ceil(log(max / min) /
// log(gamma)) counters (1 ms to 1000 s at a = 0.5 %: 1375 counters, 11 KiB), allocated once.
//
// The rank convention is the kiosk's exact percentile's: the value of rank ceil(q * n) (1-based) of
// the n values in ascending order.
//
// Throws std::invalid_argument for a relative accuracy outside (0, 0.5) or a range that is not
// 0 < min_value < max_value.
#pragma once

#include <cstdint>
#include <vector>

namespace mogao {

class QuantileSketch {
public:
    QuantileSketch(double relative_accuracy, double min_value, double max_value);

    void add(double value);
    [[nodiscard]] std::uint64_t count() const { return count_; }
    // q in [0, 1]; 0 when nothing was added.
    [[nodiscard]] double quantile(double q) const;

private:
    [[nodiscard]] std::size_t index(double value) const;

    double log_gamma_;
    double min_value_;
    double max_value_;
    int min_index_;  // the bucket of min_value (bucket 0 of counts_)
    std::vector<std::uint64_t> counts_;
    std::uint64_t non_positive_ = 0;
    std::uint64_t count_ = 0;
};

}  // namespace mogao
