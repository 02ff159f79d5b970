// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/schedule/balance_efficiency.h"

#include <algorithm>
#include <stdexcept>

namespace mogao {

double balance_efficiency(const Assignment& assignment, const CostMap& actual) {
    if (assignment.rects.empty()) {
        throw std::invalid_argument("balance_efficiency: Assignment.rects must hold at least 1 rank (got 0)");
    }
    double sum = 0.0;
    double worst = 0.0;
    for (const auto& rects : assignment.rects) {
        double rank_cost = 0.0;
        for (const PixelRect& rect : rects) {
            rank_cost += actual.sum(rect);
        }
        sum += rank_cost;
        worst = std::max(worst, rank_cost);
    }
    if (worst <= 0.0) {
        return 1.0;
    }
    return sum / static_cast<double>(assignment.rects.size()) / worst;
}

}  // namespace mogao
