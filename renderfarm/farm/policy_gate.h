// SPDX-License-Identifier: Apache-2.0
// PolicyGate: what the serving farm does to each request before rendering it. The view policy of
// the appliance that sent it (view_policy.h, view_policy_file.h), then the farm's request bounds
// (request_policy.h). Never refuses: a request outside either is moved or degraded, and each
// change is logged once per session and change of decision (a session sending 60 such requests a
// second logs once). Counts the changed requests for the log and the metrics.
//
// Errors: the constructor throws std::invalid_argument naming the bad policy field; apply() does
// not throw for a validated request.
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "renderfarm/farm/request_policy.h"
#include "renderfarm/farm/view_policy_file.h"
#include "renderfarm/scene/scene.h"

namespace mogao {

class PolicyGate {
public:
    PolicyGate(const Scene& scene, RequestPolicy policy, ViewPolicies view_policies);

    // `appliance`: the certificate common name of the request's session (empty: the farm's policy).
    [[nodiscard]] ViewRequest apply(const ViewRequest& request, const std::string& appliance);
    [[nodiscard]] std::uint64_t changed() const { return changed_; }

private:
    LightCounts lights_;
    Viewer viewer_;
    RequestPolicy policy_;
    ViewPolicies view_policies_;
    std::map<std::uint64_t, std::string> logged_;  // by session: the last change logged
    std::uint64_t changed_ = 0;
};

}  // namespace mogao
