// SPDX-License-Identifier: Apache-2.0
#include "appliance/navigation/low_pass_filter.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "appliance/navigation/one_euro_filter.h"

namespace mogao {

LowPassFilter::LowPassFilter(double cutoff_hz) : cutoff_hz_(cutoff_hz) {
    if (!(cutoff_hz > 0.0 && std::isfinite(cutoff_hz))) {
        throw std::invalid_argument("LowPassFilter: cutoff_hz = " + std::to_string(cutoff_hz) +
                                    " must be finite and > 0");
    }
}

double LowPassFilter::filter(double x, double t_s) {
    if (!std::isfinite(x) || !std::isfinite(t_s)) return y_;  // ignored: would poison the state
    if (!initialized_) {
        initialized_ = true;
        y_ = x;
        t_ = t_s;
        return y_;
    }
    const double dt = t_s - t_;
    if (!(dt > 0.0)) return y_;
    y_ += smoothing_factor(cutoff_hz_, dt) * (x - y_);
    t_ = t_s;
    return y_;
}

}  // namespace mogao
