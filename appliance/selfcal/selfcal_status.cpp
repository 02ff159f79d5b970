// SPDX-License-Identifier: Apache-2.0
// Text form of the self-recalibration state (selfcal_status.h).
#include "appliance/selfcal/selfcal_status.h"

#include <cstdio>

namespace mogao::selfcal {

const char* to_key(SelfcalState state) {
    switch (state) {
        case SelfcalState::calibrated:
            return "calibrated";
        case SelfcalState::drift_detected:
            return "drift_detected";
        case SelfcalState::correcting:
            return "correcting";
        case SelfcalState::cannot_correct:
            return "cannot_correct";
    }
    return "unknown";
}

const char* to_string(SelfcalState state) {
    switch (state) {
        case SelfcalState::calibrated:
            return "calibrated";
        case SelfcalState::drift_detected:
            return "drift detected";
        case SelfcalState::correcting:
            return "correcting";
        case SelfcalState::cannot_correct:
            return "cannot correct (needs a full calibration)";
    }
    return "?";
}

std::string SelfcalStatus::text() const {
    char buf[160];
    std::snprintf(buf, sizeof buf, "selfcal t=%.2fs state=%s", t_s, to_string(state));
    std::string out = buf;
    if (from_pattern) out += " measured=pattern pair";
    if (waiting) out += " waiting=insufficient evidence";
    if (!reason.empty()) out += " (" + reason + ")";
    std::snprintf(buf, sizeof buf, " camera %.3f deg", camera_rotation_deg);
    out += buf;
    for (const ProjectorStatus& p : projectors) {
        std::snprintf(buf, sizeof buf, "; %s: %d matches%s drift %.2f px (%.3f deg, %.1f mm)", p.id.c_str(), p.matches,
                      p.measured ? "" : " (unmeasured)", p.drift_px, p.rotation_deg, p.shift_mm);
        out += buf;
    }
    return out;
}

}  // namespace mogao::selfcal
