// SPDX-License-Identifier: Apache-2.0
#include "appliance/navigation/one_euro_filter.h"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace mogao {

double smoothing_factor(double cutoff_hz, double dt_s) {
    const double tau = 1.0 / (2.0 * std::numbers::pi * cutoff_hz);
    return 1.0 / (1.0 + tau / dt_s);
}

OneEuroFilter::OneEuroFilter(const OneEuroParams& params) : params_(params) {
    const auto positive = [](const char* name, double v) {
        if (!(v > 0.0 && std::isfinite(v))) {
            throw std::invalid_argument(std::string("OneEuroParams.") + name + " = " + std::to_string(v) +
                                        " must be finite and > 0");
        }
    };
    positive("min_cutoff_hz", params.min_cutoff_hz);
    positive("d_cutoff_hz", params.d_cutoff_hz);
    if (!(params.beta >= 0.0 && std::isfinite(params.beta))) {
        throw std::invalid_argument("OneEuroParams.beta = " + std::to_string(params.beta) + " must be finite and >= 0");
    }
}

double OneEuroFilter::filter(double x, double t_s) {
    // A non-finite sample would make x^ infinite (then inf - inf = NaN forever); a non-finite time
    // would freeze the filter (every later dt negative).
    if (!std::isfinite(x) || !std::isfinite(t_s)) return x_;
    if (!initialized_) {
        initialized_ = true;
        x_ = x;
        dx_ = 0.0;
        t_ = t_s;
        return x_;
    }
    const double dt = t_s - t_;
    if (!(dt > 0.0)) return x_;
    const double dx = (x - x_) / dt;
    dx_ += smoothing_factor(params_.d_cutoff_hz, dt) * (dx - dx_);
    const double cutoff = params_.min_cutoff_hz + params_.beta * std::abs(dx_);
    x_ += smoothing_factor(cutoff, dt) * (x - x_);
    t_ = t_s;
    return x_;
}

}  // namespace mogao
