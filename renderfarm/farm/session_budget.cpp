// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/session_budget.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "renderfarm/link/link_server.h"

namespace mogao {

SessionBudgets::SessionBudgets(TimeBudget budget, LightCounts lights) : budget_(budget), lights_(lights) {
    if (!(budget_.frame_s >= 0) || !std::isfinite(budget_.frame_s))
        throw std::invalid_argument(fmt::format("TimeBudget.frame_s = {} must be finite and >= 0", budget_.frame_s));
    if (!(budget_.aim > 0 && budget_.aim <= 1))
        throw std::invalid_argument(fmt::format("TimeBudget.aim = {} must be in (0, 1]", budget_.aim));
    if (!(budget_.band >= 1) || !std::isfinite(budget_.band))
        throw std::invalid_argument(fmt::format("TimeBudget.band = {} must be finite and >= 1", budget_.band));
    if (!(budget_.share_min_scale >= 0 && budget_.share_min_scale <= 1))
        throw std::invalid_argument(
            fmt::format("TimeBudget.share_min_scale = {} must be in [0, 1]", budget_.share_min_scale));
}

double SessionBudgets::rate(const std::string& who) const {
    const auto found = appliances_.find(who);
    return found == appliances_.end() ? 0.0 : found->second.rays_per_s;
}

BudgetDecision SessionBudgets::apply(const ViewRequest& request, const std::string& who, double share_s) {
    BudgetDecision out{request, false, {}, 0.0, budget_.frame_s};
    const double rays_per_s = rate(who);
    if (budget_.frame_s <= 0 || rays_per_s <= 0) return out;
    if (std::isfinite(share_s) && share_s > 0) out.limit_s = std::min(budget_.frame_s, share_s);
    out.predicted_s = estimated_rays(request, lights_) / rays_per_s;
    if (out.predicted_s <= out.limit_s) return out;
    RequestPolicy bound;
    bound.max_megapixels = 1e6;  // pixels are bounded by the request policy already
    bound.max_gigarays = rays_per_s * budget_.aim * out.limit_s / 1e9;
    const bool share_governs = out.limit_s < budget_.frame_s;
    if (share_governs) bound.min_resolution_scale = budget_.share_min_scale;
    PolicyDecision degraded = apply_request_policy(request, lights_, bound);
    if (share_governs && degraded.rendered_rays / rays_per_s > budget_.frame_s) {
        // The floor does not fit the frame budget itself: held to frame_s, with no floor.
        out.limit_s = budget_.frame_s;
        bound.min_resolution_scale = 0.0;
        bound.max_gigarays = rays_per_s * budget_.aim * out.limit_s / 1e9;
        degraded = apply_request_policy(request, lights_, bound);
    }
    out.view = degraded.view;
    out.degraded = degraded.degraded;
    out.changes = degraded.changes;
    out.predicted_s = degraded.rendered_rays / rays_per_s;
    if (out.predicted_s > budget_.frame_s) {
        throw RequestRefused(fmt::format(
            "'{}' asks for frames this farm cannot render within its frame budget of {} s: estimated {:.1f} s "
            "even degraded ({}) at the {:.3g} rays/s its frames measured; ask for fewer pixels or samples",
            who, budget_.frame_s, out.predicted_s, out.changes, rays_per_s));
    }
    return out;
}

void SessionBudgets::observe(const std::string& who, const ViewRequest& rendered, double full_seconds) {
    if (budget_.frame_s <= 0 || !(full_seconds > 0) || !std::isfinite(full_seconds)) return;
    const double measured = estimated_rays(rendered, lights_) / full_seconds;
    if (!(measured > 0)) return;
    auto found = appliances_.find(who);
    if (found == appliances_.end()) {
        if (appliances_.size() >= std::max<std::size_t>(1, budget_.max_appliances)) {
            appliances_.erase(
                std::min_element(appliances_.begin(), appliances_.end(),
                                 [](const auto& a, const auto& b) { return a.second.last_used < b.second.last_used; }));
        }
        found = appliances_.try_emplace(who).first;
    }
    Appliance& a = found->second;
    a.last_used = ++uses_;
    if (a.rays_per_s <= 0 || measured < a.rays_per_s / budget_.band || measured > a.rays_per_s * budget_.band)
        a.rays_per_s = measured;
}

}  // namespace mogao
