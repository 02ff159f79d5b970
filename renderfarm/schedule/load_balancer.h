// SPDX-License-Identifier: Apache-2.0
// Sort-first load balancing: which pixels of the next frame each render rank traces.
//
// A LoadBalancer turns a predicted CostMap into an Assignment of pixel rects to ranks 0..ranks-1.
// Every balancer's assignment tiles the image exactly once: each pixel is in exactly one rect of
// exactly one rank. Rects may be empty (a rank then renders nothing), and a rank may have no rects.
// Pixel convention and rects: common/pixel_rect.h. Algorithms: docs/load-balancing.md.
#pragma once

#include <memory>
#include <string_view>
#include <vector>

#include "common/pixel_rect.h"
#include "renderfarm/schedule/cost_map.h"

namespace mogao {

struct Assignment {
    std::vector<std::vector<PixelRect>> rects;  // per render rank, index 0..ranks-1
    std::vector<double> predicted_cost;         // per rank, seconds, as predicted by the map given to assign()
};

class LoadBalancer {
public:
    // Upper bound on ranks, only to turn a garbage rank count into an error instead of a huge allocation.
    static constexpr int kMaxRanks = 1 << 16;

    virtual ~LoadBalancer() = default;
    // Splits predicted.size() over `ranks` ranks (1 <= ranks <= kMaxRanks, else std::invalid_argument).
    // predicted_cost[r] is predicted.sum() over rank r's rects, whatever the balancer used to split.
    [[nodiscard]] virtual Assignment assign(const CostMap& predicted, int ranks) const = 0;
    [[nodiscard]] virtual std::string_view name() const = 0;
};

// name: "pbt" (PbtBalancer, snap_or_tile = snap in pixels), "equal" (EqualSplitBalancer, snap),
// "roundrobin" (RoundRobinBalancer, tile size in pixels). snap_or_tile >= 1.
// Throws std::invalid_argument listing the valid names for an unknown name, or for snap_or_tile < 1.
[[nodiscard]] std::unique_ptr<LoadBalancer> make_load_balancer(std::string_view name, int snap_or_tile);

// Names accepted by make_load_balancer, in the order the simulator reports them.
[[nodiscard]] std::vector<std::string_view> load_balancer_names();

// Throws std::invalid_argument unless 1 <= ranks <= LoadBalancer::kMaxRanks (shared by balancers).
void check_rank_count(int ranks);

}  // namespace mogao
