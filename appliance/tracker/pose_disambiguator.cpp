// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/pose_disambiguator.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace mogao {

PoseDisambiguator::PoseDisambiguator(const DisambiguationParams& params) : params_(params) {
    if (!(params.ambiguity_ratio >= 1.0 && std::isfinite(params.ambiguity_ratio))) {
        throw std::invalid_argument("DisambiguationParams.ambiguity_ratio " + std::to_string(params.ambiguity_ratio) +
                                    " must be finite and >= 1");
    }
    if (!(params.ambiguity_slack_px >= 0.0 && std::isfinite(params.ambiguity_slack_px))) {
        throw std::invalid_argument("DisambiguationParams.ambiguity_slack_px " +
                                    std::to_string(params.ambiguity_slack_px) + " must be finite and >= 0");
    }
    if (!(params.min_separation_deg >= 0.0 && params.min_separation_deg <= 180.0)) {
        throw std::invalid_argument("DisambiguationParams.min_separation_deg " +
                                    std::to_string(params.min_separation_deg) + " outside [0, 180]");
    }
}

TagPose PoseDisambiguator::choose(std::span<const TagPose> candidates) {
    if (candidates.empty()) throw std::invalid_argument("PoseDisambiguator::choose: no candidate poses");
    const TagPose* pick = &candidates[0];
    ambiguous_ = candidates.size() > 1 &&
                 candidates[1].reprojection_rms_px <=
                     params_.ambiguity_ratio * candidates[0].reprojection_rms_px + params_.ambiguity_slack_px &&
                 rotation_angle_deg(candidates[0].rotation, candidates[1].rotation) >= params_.min_separation_deg;
    if (ambiguous_ && previous_) {
        const double d0 = rotation_angle_deg(previous_->rotation, candidates[0].rotation);
        const double d1 = rotation_angle_deg(previous_->rotation, candidates[1].rotation);
        if (d1 < d0) pick = &candidates[1];
    }
    // Every choice becomes the reference, a first ambiguous guess too: the next frames then stay
    // consistent with what was shown, and an unambiguous frame corrects a wrong guess.
    previous_ = *pick;
    return *pick;
}

}  // namespace mogao
