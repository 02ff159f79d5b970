// SPDX-License-Identifier: Apache-2.0
#include "appliance/warp/response_curve.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mogao {

ResponseCurve make_gamma_response(double gamma, int entries) {
    if (!(gamma > 0.0 && gamma <= 10.0)) {
        throw std::invalid_argument("make_gamma_response: gamma " + std::to_string(gamma) + " is outside (0, 10]");
    }
    if (entries < 2 || entries > kMaxResponseEntries) {
        throw std::invalid_argument("make_gamma_response: entries " + std::to_string(entries) + " is outside [2, " +
                                    std::to_string(kMaxResponseEntries) + "]");
    }
    std::vector<float> lut(static_cast<std::size_t>(entries));
    const double last = entries - 1;
    for (int k = 0; k < entries; ++k) {
        lut[static_cast<std::size_t>(k)] = static_cast<float>(std::pow(k / last, 1.0 / gamma));
    }
    return ResponseCurve{{lut, lut, lut}};
}

void validate_response(const ResponseCurve& curve, std::string_view what) {
    const std::string who(what);
    const std::size_t n = curve.lut[0].size();
    for (std::size_t c = 0; c < 3; ++c) {
        const std::vector<float>& lut = curve.lut[c];
        const std::string ch = who + ".lut[" + std::to_string(c) + "]";
        if (lut.size() < 2 || lut.size() > static_cast<std::size_t>(kMaxResponseEntries)) {
            throw std::invalid_argument(ch + ": " + std::to_string(lut.size()) + " entries, outside [2, " +
                                        std::to_string(kMaxResponseEntries) + "]");
        }
        if (lut.size() != n) {
            throw std::invalid_argument(ch + ": " + std::to_string(lut.size()) + " entries but channel 0 has " +
                                        std::to_string(n) + " (all channels must have the same length)");
        }
        for (std::size_t k = 0; k < lut.size(); ++k) {
            const float value = lut[k];
            if (!(value >= 0.0F && value <= 1.0F)) {
                throw std::invalid_argument(ch + "[" + std::to_string(k) + "] = " + std::to_string(value) +
                                            " is outside [0, 1] (or not finite)");
            }
            if (k > 0 && value < lut[k - 1]) {
                throw std::invalid_argument(ch + "[" + std::to_string(k) + "] = " + std::to_string(value) +
                                            " is below the previous entry " + std::to_string(lut[k - 1]) +
                                            " (the table must be non-decreasing)");
            }
        }
    }
}

double apply_lut(const std::vector<float>& lut, double linear) {
    // NaN fails both comparisons: treat it as no light rather than index with it.
    const double x = (linear > 0.0) ? std::min(linear, 1.0) : 0.0;
    const double position = x * static_cast<double>(lut.size() - 1);
    const auto k = std::min(static_cast<std::size_t>(position), lut.size() - 2);
    const double t = position - static_cast<double>(k);
    return lut[k] + (static_cast<double>(lut[k + 1]) - lut[k]) * t;
}

double invert_lut(const std::vector<float>& lut, double signal) {
    if (!(signal > static_cast<double>(lut.front()))) return 0.0;  // also NaN
    if (signal >= static_cast<double>(lut.back())) {
        // Lowest linear value reaching the top signal (a flat top resolves to its start).
        const auto first = std::lower_bound(lut.begin(), lut.end(), lut.back());
        return static_cast<double>(first - lut.begin()) / static_cast<double>(lut.size() - 1);
    }
    // First sample >= signal; lut[k] < signal <= lut[k + 1], so the segment is not flat.
    const auto upper = std::lower_bound(lut.begin() + 1, lut.end(), signal,
                                        [](float entry, double s) { return static_cast<double>(entry) < s; });
    const auto k = static_cast<std::size_t>(upper - lut.begin()) - 1;
    const double t = (signal - lut[k]) / (static_cast<double>(lut[k + 1]) - lut[k]);
    return (static_cast<double>(k) + t) / static_cast<double>(lut.size() - 1);
}

float apply_response(const ResponseCurve& curve, int channel, float linear) {
    return static_cast<float>(apply_lut(curve.lut[static_cast<std::size_t>(channel)], linear));
}

float invert_response(const ResponseCurve& curve, int channel, float signal) {
    return static_cast<float>(invert_lut(curve.lut[static_cast<std::size_t>(channel)], signal));
}

}  // namespace mogao
