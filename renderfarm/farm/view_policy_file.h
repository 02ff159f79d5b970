// SPDX-License-Identifier: Apache-2.0
// One view policy per appliance certificate (the view policy can restrict the
// resolution and field of view to the appliance's screen). A farm serving several museums knows each
// appliance's screen and content resolution; a certificate holder then gets only views its own
// screen can show, whatever it asks.
//
// File (`mogao-farm serve --view-policy FILE`, JSON, read once at start):
//   {
//     "appliances": {
//       "museum-1": {
//         "screen": {"radius_m": 3.0, "arc_deg": 150, "bottom_m": 0.2, "top_m": 2.8, "eye_height_m": 1.6},
//         "max_guard_deg": 10,
//         "max_size": [5760, 1080],
//         "visitable_area": true,
//         "min_fov_deg": 0
//       }
//     }
//   }
// Keys of an appliance entry are those of ViewPolicy (view_policy.h; metres, degrees, pixels); each
// entry starts from the farm's policy (the --view-* flags) and replaces what it names. Names are
// certificate common names (`mogao-farm pki issue NAME`). Appliances not listed get the farm's policy.
//
// Errors: read_view_policies throws std::runtime_error naming the file, the JSON path of the bad
// field (e.g. "appliances.museum-1.max_size") and the limit: unreadable or not JSON, an unknown
// key (a typo must not silently leave a museum unrestricted), a wrong type, a value out of range.
#pragma once

#include <filesystem>
#include <map>
#include <string>

#include "renderfarm/farm/view_policy.h"

namespace mogao {

struct ViewPolicies {
    ViewPolicy farm;                               // appliances not listed
    std::map<std::string, ViewPolicy> appliances;  // by certificate common name

    // The policy of `appliance` (its certificate's common name; empty or unknown: the farm's).
    [[nodiscard]] const ViewPolicy& of(const std::string& appliance) const;
};

[[nodiscard]] ViewPolicies read_view_policies(const std::filesystem::path& file, const ViewPolicy& farm);

}  // namespace mogao
