// SPDX-License-Identifier: Apache-2.0
// PolicyGate: what the serving farm does to each request before rendering it. The view policy of
// the appliance that sent it (view_policy.h, view_policy_file.h), then the farm's request bounds
// (request_policy.h). Never refuses: a request outside either is moved or degraded. The changes are
// logged through a LogThrottle (log_throttle.h): a session's first change of each kind (view policy,
// request bounds) at once, then at most one line a minute with the count held back, because the
// line carries the values (a visitor pressing against the visitable area's edge moves the eye, and
// so the line, with every request). Counts the changed requests for the log and the metrics.
//
// Errors: the constructor throws std::invalid_argument naming the bad policy field; apply() does
// not throw for a validated request.
#pragma once

#include <cstdint>
#include <string>

#include "renderfarm/farm/log_throttle.h"
#include "renderfarm/farm/request_policy.h"
#include "renderfarm/farm/view_policy_file.h"
#include "renderfarm/scene/scene.h"

namespace mogao {

class PolicyGate {
public:
    PolicyGate(const Scene& scene, RequestPolicy policy, ViewPolicies view_policies);

    // `appliance`: the certificate common name of the request's session (empty: the farm's policy);
    // `now_s`: the log throttle's clock.
    [[nodiscard]] ViewRequest apply(const ViewRequest& request, const std::string& appliance,
                                    double now_s = log_clock_s());
    [[nodiscard]] std::uint64_t changed() const { return changed_; }

private:
    LightCounts lights_;
    Viewer viewer_;
    RequestPolicy policy_;
    ViewPolicies view_policies_;
    LogThrottle log_;
    std::uint64_t changed_ = 0;
};

}  // namespace mogao
