// SPDX-License-Identifier: Apache-2.0
// PoseDisambiguator: picks one of the two IPPE poses of a tag per frame (tag_pose.h).
//
// Rule. The second solution is a real alternative ("ambiguous") when its reprojection RMS is below
// ambiguity_ratio * best + ambiguity_slack_px and it is at least min_separation_deg away from the
// best; otherwise the best is taken. When ambiguous, the
// candidate whose rotation is closest (rotation_angle_deg) to the previous frame's choice is
// taken: a hand cannot flip a tag's tilt by tens of degrees between two frames, and the two IPPE
// solutions differ by roughly twice the tilt, so continuity separates them. With no previous
// choice (first frame, or after reset()) the best is taken. An unambiguous frame re-anchors the
// history, so a wrong first guess does not persist once the tag is tilted clearly. Continuity
// removes flips between frames; it cannot tell which solution is right in a frame that is
// ambiguous from the start (measured: pose_disambiguator_test, docs/tracking.md).
//
// A flip that survives this (both candidates far from the previous pose) is left to the
// navigation's rate gate (appliance/navigation/flip_gate.h), which rejects implausible jumps.
#pragma once

#include <optional>
#include <span>

#include "appliance/tracker/tag_pose.h"

namespace mogao {

struct DisambiguationParams {
    double ambiguity_ratio = 3.0;     // >= 1
    double ambiguity_slack_px = 0.3;  // >= 0: about the RMS corner noise of a still tag
    // Candidates closer than this (rotation angle between them) are not a flip worth avoiding:
    // both are near the truth, and following the history would only lock in noise. [0, 180].
    double min_separation_deg = 10.0;
};

class PoseDisambiguator {
public:
    // Throws std::invalid_argument naming the bad parameter and its limit.
    explicit PoseDisambiguator(const DisambiguationParams& params = {});

    // The chosen pose. Throws std::invalid_argument if `candidates` is empty.
    [[nodiscard]] TagPose choose(std::span<const TagPose> candidates);

    // Forget the history (call when the tag has been lost for a while).
    void reset() { previous_.reset(); }

    // Whether the last choose() had two plausible candidates.
    [[nodiscard]] bool last_was_ambiguous() const { return ambiguous_; }

private:
    DisambiguationParams params_;
    std::optional<TagPose> previous_;
    bool ambiguous_ = false;
};

}  // namespace mogao
