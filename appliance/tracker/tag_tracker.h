// SPDX-License-Identifier: Apache-2.0
// TagTracker: one frame in, the visitor's tag pose out. Detection (tag_detector.h), both IPPE
// poses (tag_pose.h), then the choice between them (pose_disambiguator.h). The visitor holds one
// tag: with tag_id < 0 the largest detected tag of the family is used, else only that id.
#pragma once

#include <cstdint>

#include "appliance/tracker/camera_intrinsics.h"
#include "appliance/tracker/detector_settings.h"
#include "appliance/tracker/pose_disambiguator.h"
#include "appliance/tracker/tag_detector.h"
#include "appliance/tracker/tag_pose.h"
#include "drivers/camera/camera_frame.h"

namespace mogao {

struct TrackerConfig {
    DetectorSettings detector;
    CameraIntrinsics camera;   // must match the frames' size (use rescale() for a binned mode)
    double tag_size_m = 0.10;  // side of the black border square
    int tag_id = -1;           // -1: the largest tag of the family
    DisambiguationParams disambiguation;
    // After the tag has been unseen this long, the pose history is forgotten (a tag brought back
    // into view may be held quite differently).
    double forget_after_s = 0.5;
};

struct TrackedTag {
    std::int64_t timestamp_ns = 0;  // the frame's
    bool visible = false;           // false: no (matching) tag in this frame; the rest is unset
    int id = -1;
    TagPose pose;
    bool ambiguous = false;  // the IPPE choice was made by continuity
    TagDetection detection;
};

class TagTracker {
public:
    // Throws std::invalid_argument for bad settings, intrinsics or tag size.
    explicit TagTracker(const TrackerConfig& config);

    // Throws std::invalid_argument if the frame's size differs from config.camera's.
    [[nodiscard]] TrackedTag track(const CameraFrame& frame);

    [[nodiscard]] const TrackerConfig& config() const { return config_; }

private:
    TrackerConfig config_;
    TagDetector detector_;
    PoseDisambiguator disambiguator_;
    std::int64_t last_seen_ns_ = 0;
    bool seen_ = false;
};

}  // namespace mogao
