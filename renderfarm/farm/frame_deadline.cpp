// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/frame_deadline.h"

#include <algorithm>

namespace mogao {

double frame_cost_units(const ViewRequest& view) {
    const ImageSize size = render_size(view);
    return double(size.width) * double(size.height) * std::max(1, view.quality.spp) *
           (std::max(0, view.quality.max_bounces) + 1);
}

double FrameDeadline::seconds_for(double cost) const {
    if (settings_.max_s <= 0) return 0.0;
    if (settings_.factor <= 0 || rates_.empty() || !(cost > 0)) return settings_.max_s;
    const double rate = *std::max_element(rates_.begin(), rates_.end());
    return std::clamp(settings_.factor * rate * cost, std::min(settings_.min_s, settings_.max_s), settings_.max_s);
}

void FrameDeadline::observe(double cost, double seconds) {
    if (!(cost > 0) || !(seconds >= 0)) return;
    rates_.push_back(seconds / cost);
    while (rates_.size() > std::max<std::size_t>(1, settings_.window)) rates_.pop_front();
}

}  // namespace mogao
