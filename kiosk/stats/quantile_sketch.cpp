// SPDX-License-Identifier: Apache-2.0
#include "kiosk/stats/quantile_sketch.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mogao {

QuantileSketch::QuantileSketch(double relative_accuracy, double min_value, double max_value)
    : min_value_(min_value), max_value_(max_value) {
    if (!(relative_accuracy > 0 && relative_accuracy < 0.5))
        throw std::invalid_argument("QuantileSketch: relative accuracy must be in (0, 0.5)");
    if (!(min_value > 0 && min_value < max_value))
        throw std::invalid_argument("QuantileSketch: the range must satisfy 0 < min_value < max_value");
    log_gamma_ = std::log((1 + relative_accuracy) / (1 - relative_accuracy));
    min_index_ = static_cast<int>(std::ceil(std::log(min_value) / log_gamma_));
    const int max_index = static_cast<int>(std::ceil(std::log(max_value) / log_gamma_));
    counts_.assign(static_cast<std::size_t>(max_index - min_index_ + 1), 0);
}

std::size_t QuantileSketch::index(double value) const {
    const double clamped = std::clamp(value, min_value_, max_value_);
    const int i = static_cast<int>(std::ceil(std::log(clamped) / log_gamma_)) - min_index_;
    return static_cast<std::size_t>(std::clamp(i, 0, static_cast<int>(counts_.size()) - 1));
}

void QuantileSketch::add(double value) {
    ++count_;
    if (!(value > 0)) {
        ++non_positive_;
        return;
    }
    ++counts_[index(value)];
}

double QuantileSketch::quantile(double q) const {
    if (count_ == 0) return 0;
    const auto rank = std::max<std::uint64_t>(
        1, static_cast<std::uint64_t>(std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(count_))));
    std::uint64_t seen = non_positive_;
    if (rank <= seen) return 0;
    for (std::size_t i = 0; i < counts_.size(); ++i) {
        seen += counts_[i];
        if (rank <= seen) {
            const double gamma = std::exp(log_gamma_);
            const double upper = std::exp(log_gamma_ * (static_cast<int>(i) + min_index_));
            return std::clamp(2 * upper / (gamma + 1), min_value_, max_value_);
        }
    }
    return max_value_;
}

}  // namespace mogao
