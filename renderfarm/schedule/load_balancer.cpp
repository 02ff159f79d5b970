// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/schedule/load_balancer.h"

#include <stdexcept>
#include <string>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "renderfarm/schedule/pbt.h"
#include "renderfarm/schedule/round_robin.h"

namespace mogao {

std::vector<std::string_view> load_balancer_names() { return {"pbt", "equal", "roundrobin"}; }

void check_rank_count(int ranks) {
    if (ranks < 1 || ranks > LoadBalancer::kMaxRanks) {
        throw std::invalid_argument(fmt::format("ranks must be in [1, {}] (got {})", LoadBalancer::kMaxRanks, ranks));
    }
}

std::unique_ptr<LoadBalancer> make_load_balancer(std::string_view name, int snap_or_tile) {
    if (name == "pbt") {
        return std::make_unique<PbtBalancer>(snap_or_tile);
    }
    if (name == "equal") {
        return std::make_unique<EqualSplitBalancer>(snap_or_tile);
    }
    if (name == "roundrobin") {
        return std::make_unique<RoundRobinBalancer>(snap_or_tile);
    }
    throw std::invalid_argument(
        fmt::format("load balancer name must be one of {} (got \"{}\")", fmt::join(load_balancer_names(), ", "), name));
}

}  // namespace mogao
