// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/tag_tracker.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace mogao {
namespace {

double quad_area(const TagDetection& d) {  // shoelace formula
    double a = 0.0;
    for (std::size_t i = 0; i < 4; ++i) {
        const auto& p = d.corners[i];
        const auto& q = d.corners[(i + 1) % 4];
        a += p.x() * q.y() - q.x() * p.y();
    }
    return std::abs(a) / 2.0;
}

}  // namespace

TagTracker::TagTracker(const TrackerConfig& config)
    : config_(config), detector_(config.detector), disambiguator_(config.disambiguation) {
    validate(config_.camera);
    if (!(config_.tag_size_m > 0.0 && config_.tag_size_m <= 10.0)) {
        throw std::invalid_argument("TrackerConfig.tag_size_m " + std::to_string(config_.tag_size_m) +
                                    " outside (0, 10]");
    }
    if (config_.tag_id >= detector_.family().code_count()) {
        throw std::invalid_argument("TrackerConfig.tag_id " + std::to_string(config_.tag_id) + " outside [-1, " +
                                    std::to_string(detector_.family().code_count()) + ") of " +
                                    detector_.family().name());
    }
    if (!(config_.forget_after_s >= 0.0)) throw std::invalid_argument("TrackerConfig.forget_after_s must be >= 0");
}

TrackedTag TagTracker::track(const CameraFrame& frame) {
    if (frame.image.width != config_.camera.width || frame.image.height != config_.camera.height) {
        throw std::invalid_argument("TagTracker: frame " + std::to_string(frame.image.width) + "x" +
                                    std::to_string(frame.image.height) + " but the calibration is for " +
                                    std::to_string(config_.camera.width) + "x" + std::to_string(config_.camera.height));
    }
    TrackedTag out;
    out.timestamp_ns = frame.timestamp_ns;
    const auto detections = detector_.detect(frame.image);
    const TagDetection* pick = nullptr;
    for (const auto& d : detections) {
        if (config_.tag_id >= 0 ? d.id == config_.tag_id : (pick == nullptr || quad_area(d) > quad_area(*pick)))
            pick = &d;
    }
    if (pick == nullptr) return out;
    if (seen_ && static_cast<double>(frame.timestamp_ns - last_seen_ns_) > config_.forget_after_s * 1e9)
        disambiguator_.reset();
    const auto candidates = solve_tag_pose(pick->corners, config_.camera, config_.tag_size_m);
    if (candidates.empty()) return out;
    out.visible = true;
    out.id = pick->id;
    out.detection = *pick;
    out.pose = disambiguator_.choose(candidates);
    out.ambiguous = disambiguator_.last_was_ambiguous();
    seen_ = true;
    last_seen_ns_ = frame.timestamp_ns;
    return out;
}

}  // namespace mogao
