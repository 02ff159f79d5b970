// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/schedule/request_pace.h"

#include <algorithm>
#include <cmath>

namespace mogao {

void RequestPace::note(double period_s, double wait_s, double share) {
    if (!(period_s > 0.0) || !std::isfinite(period_s)) return;
    constexpr double kWeight = 0.3;  // of the newest request
    const auto weigh = [](double mean, double x) { return mean > 0.0 ? (1.0 - kWeight) * mean + kWeight * x : x; };
    period_s_ = weigh(period_s_, period_s);
    wait_s_ = weigh(wait_s_, std::isfinite(wait_s) ? std::max(wait_s, 0.0) : 0.0);
    const double rest = (1.0 - share) * period_s_;
    if (!paced_ && wait_s_ >= rest / 2.0) paced_ = true;
    else if (paced_ && wait_s_ < rest / 6.0) paced_ = false;
}

double RequestPace::target(double target_s, double share, double max_factor) const {
    if (!paced_) return target_s;
    return std::clamp(share * period_s_, target_s, max_factor * target_s);
}

}  // namespace mogao
