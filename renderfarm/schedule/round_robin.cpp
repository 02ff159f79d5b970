// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/schedule/round_robin.h"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

namespace mogao {

RoundRobinBalancer::RoundRobinBalancer(int tile) : tile_(tile) {
    if (tile < 1) {
        throw std::invalid_argument(fmt::format("round-robin tile must be >= 1 pixel (got {})", tile));
    }
}

Assignment RoundRobinBalancer::assign(const CostMap& predicted, int ranks) const {
    check_rank_count(ranks);
    const ImageSize size = predicted.size();
    Assignment out;
    out.rects.resize(static_cast<std::size_t>(ranks));
    out.predicted_cost.assign(static_cast<std::size_t>(ranks), 0.0);
    std::size_t next = 0;
    for (int y = 0; y < size.height; y += tile_) {
        for (int x = 0; x < size.width; x += tile_) {
            const PixelRect rect{x, y, std::min(x + tile_, size.width), std::min(y + tile_, size.height)};
            out.rects[next].push_back(rect);
            out.predicted_cost[next] += predicted.sum(rect);
            next = (next + 1) % out.rects.size();
        }
    }
    return out;
}

}  // namespace mogao
