// SPDX-License-Identifier: Apache-2.0
// Round-robin tile dealing: the classic static alternative to a cost-driven sort-first split.
//
// The image is cut into square tiles of `tile` pixels aligned on absolute multiples of `tile` (the
// last column and row may be partial). In scanline order (rows top to bottom, left to right in a
// row) tile i goes to rank i % ranks. Fine tiles interleave cheap and expensive regions, so the
// balance is statistically good without any prediction, at the price of more, smaller tiles per
// rank (more per-tile overhead and less ray coherence). Ranks beyond the tile count get no rects.
#pragma once

#include <string_view>

#include "renderfarm/schedule/load_balancer.h"

namespace mogao {

class RoundRobinBalancer final : public LoadBalancer {
public:
    static constexpr int kDefaultTile = 32;  // pixels

    explicit RoundRobinBalancer(int tile = kDefaultTile);  // tile >= 1, else std::invalid_argument
    [[nodiscard]] Assignment assign(const CostMap& predicted, int ranks) const override;
    [[nodiscard]] std::string_view name() const override { return "roundrobin"; }
    [[nodiscard]] int tile() const { return tile_; }

private:
    int tile_;
};

}  // namespace mogao
