// SPDX-License-Identifier: Apache-2.0
// Load-balance efficiency of a sort-first assignment, measured against the costs that really occurred.
//
// efficiency = mean over ranks of (actual cost of the rank's rects) / max over ranks of the same.
// 1.0 means every rank finishes at the same time; 1/ranks means one rank does all the work. This is
// the usual parallel efficiency of the render step when a frame waits for its slowest rank (e.g.
// Samanta et al. 1999 report balance the same way).
#pragma once

#include "renderfarm/schedule/cost_map.h"
#include "renderfarm/schedule/load_balancer.h"

namespace mogao {

// actual: the measured cost map of the frame the assignment was used for (same image as the
// assignment's rects). Ranks with no rects count as ranks with zero work.
// When no rank has any work (actual cost 0 everywhere the ranks render), returns 1.0: nothing was
// imbalanced. Throws std::invalid_argument for an assignment with 0 ranks, or (via CostMap::sum)
// for a rect outside the actual map's image.
[[nodiscard]] double balance_efficiency(const Assignment& assignment, const CostMap& actual);

}  // namespace mogao
