// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/policy_gate.h"

#include <spdlog/spdlog.h>

namespace mogao {

PolicyGate::PolicyGate(const Scene& scene, RequestPolicy policy, ViewPolicies view_policies)
    : lights_(LightCounts::of(scene)),
      viewer_(scene.viewer),
      policy_(policy),
      view_policies_(std::move(view_policies)) {
    policy_.validate();
    view_policies_.farm.validate();
    for (const auto& [name, p] : view_policies_.appliances) p.validate();
}

ViewRequest PolicyGate::apply(const ViewRequest& request, const std::string& appliance, double now_s) {
    const ViewDecision v = apply_view_policy(request, viewer_, view_policies_.of(appliance));
    const PolicyDecision d = apply_request_policy(v.view, lights_, policy_);
    if (v.changes.empty() && !d.degraded) return d.view;
    ++changed_;
    const std::string session = std::to_string(request.session);
    if (!v.changes.empty()) {
        if (const LogThrottle::Verdict t = log_.allow("view:" + session, now_s); t.write)
            spdlog::warn("session {} ({}): view outside its view policy: rendered with {}{}", request.session,
                         appliance.empty() ? "?" : appliance, v.changes, held_back_note(t.held_back));
    }
    if (d.degraded) {
        if (const LogThrottle::Verdict t = log_.allow("request:" + session, now_s); t.write)
            spdlog::warn(
                "session {}: request over the farm's bounds ({:.3g} rays estimated, limit {:.3g}; {:.3g} "
                "Mpixels, limit {:.3g}): rendered with {}{}",
                request.session, d.requested_rays, policy_.max_gigarays * 1e9,
                double(request.size.width) * request.size.height * 1e-6, policy_.max_megapixels, d.changes,
                held_back_note(t.held_back));
    }
    return d.view;
}

}  // namespace mogao
