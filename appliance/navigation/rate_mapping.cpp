// SPDX-License-Identifier: Apache-2.0
#include "appliance/navigation/rate_mapping.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mogao {

void validate(const RateAxis& a, const char* name) {
    const auto bad = [&](const std::string& what) { throw std::invalid_argument(std::string(name) + "." + what); };
    if (!(a.dead_zone >= 0.0 && std::isfinite(a.dead_zone))) bad("dead_zone must be finite and >= 0");
    if (!(a.full_scale > a.dead_zone && std::isfinite(a.full_scale))) {
        bad("full_scale " + std::to_string(a.full_scale) + " must be finite and > dead_zone " +
            std::to_string(a.dead_zone));
    }
    if (!(a.max_rate >= 0.0 && std::isfinite(a.max_rate))) bad("max_rate must be finite and >= 0");
    if (!(a.exponent >= 1.0 && a.exponent <= 4.0)) bad("exponent " + std::to_string(a.exponent) + " outside [1, 4]");
}

double rate_from_offset(double offset, const RateAxis& a) {
    const double x = std::clamp((std::abs(offset) - a.dead_zone) / (a.full_scale - a.dead_zone), 0.0, 1.0);
    if (!(x > 0.0)) return 0.0;  // inside the dead zone (or NaN offset): no motion
    return std::copysign(a.max_rate * std::pow(x, a.exponent), offset);
}

double slew_toward(double current, double target, double max_step) {
    return current + std::clamp(target - current, -max_step, max_step);
}

}  // namespace mogao
