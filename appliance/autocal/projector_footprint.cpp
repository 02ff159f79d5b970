// SPDX-License-Identifier: Apache-2.0
// A projector pixel's light at a continuous position: aperture box convolved with the defocus (projector_footprint.h).
#include "appliance/autocal/projector_footprint.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mogao::autocal {
namespace {

double normal_cdf(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }

}  // namespace

FootprintTaps footprint_taps(double t, int extent, double sigma) {
    if (!(sigma >= 0.0 && sigma <= 10.0) || extent < 1) {
        throw std::invalid_argument("footprint_taps: sigma must be in [0, 10] and the extent >= 1");
    }
    FootprintTaps taps;
    if (sigma == 0.0) {
        taps.first = std::clamp(static_cast<int>(std::floor(t)), 0, extent - 1);
        taps.count = 1;
        taps.weight[0] = 1.0;
        return taps;
    }
    const int lo = std::max(0, static_cast<int>(std::floor(t - 0.5 - 5.0 * sigma)));
    const int hi = std::min(extent - 1, static_cast<int>(std::floor(t + 0.5 + 5.0 * sigma)));
    taps.first = lo;
    for (int q = lo; q <= hi && taps.count < FootprintTaps::kMaxTaps; ++q) {
        const double d = t - (q + 0.5);  // from pixel q's centre
        taps.weight[static_cast<std::size_t>(taps.count++)] =
            normal_cdf((d + 0.5) / sigma) - normal_cdf((d - 0.5) / sigma);
    }
    return taps;
}

}  // namespace mogao::autocal
