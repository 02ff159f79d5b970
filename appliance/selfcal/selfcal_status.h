// SPDX-License-Identifier: Apache-2.0
// What the technician sees of self-recalibration: a state and a one-line text form for the
// journal and the kiosk's status file (docs/calibration.md, "Self-recalibration").
#pragma once

#include <string>
#include <vector>

namespace mogao::selfcal {

enum class SelfcalState {
    calibrated,      // every projector within the drift threshold (or not measurable this frame)
    drift_detected,  // a projector's filtered drift is above the threshold, not yet for hold_s
    correcting,      // a corrected calibration is being blended in over transition_s
    cannot_correct,  // a projector moved too far (its image half off the screen): needs a full calibration
};

[[nodiscard]] const char* to_string(SelfcalState state);
// The state as an identifier a program compares (status file, metric labels): "calibrated",
// "drift_detected", "correcting", "cannot_correct".
[[nodiscard]] const char* to_key(SelfcalState state);

struct ProjectorStatus {
    std::string id;
    int matches = 0;            // matches owned by the projector this frame
    bool measured = false;      // a pose fit entered its filter this frame
    double drift_px = 0.0;      // filtered: mean displacement of its image on the screen, its own pixels
    double rotation_deg = 0.0;  // filtered pose change: rotation angle
    double shift_mm = 0.0;      // filtered pose change: position
};

struct SelfcalStatus {
    SelfcalState state = SelfcalState::calibrated;
    double t_s = 0.0;
    bool waiting = false;              // too few features this frame: insufficient evidence, nothing decided
    bool from_pattern = false;         // measured on the fallback's pattern pair (SelfCalibrator::step_pattern)
    std::string reason;                // why waiting / cannot correct, empty otherwise
    double camera_rotation_deg = 0.0;  // camera's filtered pose change against the reference
    std::vector<ProjectorStatus> projectors;

    // One line, e.g. "selfcal t=12.5s state=calibrated proj0: 212 matches drift 0.04 px; ...".
    [[nodiscard]] std::string text() const;
};

}  // namespace mogao::selfcal
