// SPDX-License-Identifier: Apache-2.0
// TagTracker: one frame in, the visitor's tag pose out. Detection (tag_detector.h), both IPPE
// poses (tag_pose.h), then the choice between them (pose_disambiguator.h). The visitor holds one
// tag: with tag_id < 0 the largest detected tag of the family is used, else only that id.
//
// Region-of-interest tracking (RoiSettings, on by default): while the tag is followed, each frame
// is searched only in a window around the tag's predicted position -- its last corners moved by
// their velocity over the last two sightings (constant velocity) -- grown by `margin` tag sides.
// Inside the window the quad search's decimation follows the tag's apparent size: the largest
// integer d <= window_max_decimation that leaves the tag's shortest side >= window_tag_px pixels
// after decimating (a near, large tag is searched at a low resolution, a small or far one at full
// resolution, the detector settings), with a window_blur_sigma blur when d > 1 (AprilTag decimates
// by keeping every d-th pixel, so without it the sensor noise stays). Either way AprilTag decodes
// the bits and, with refine_edges, fits the edges on the full-resolution image, so the corners
// keep their accuracy (docs/tracking.md, "Region-of-interest tracking"). A whole-frame search,
// with the cheaper search settings (decimated), runs only when the window misses the tag (lost)
// and every `full_search_every` frames (to notice a second, larger tag). Corners are in
// full-frame pixels either way (the window's origin is added back exactly).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "appliance/tracker/camera_intrinsics.h"
#include "appliance/tracker/detector_settings.h"
#include "appliance/tracker/pose_disambiguator.h"
#include "appliance/tracker/tag_detector.h"
#include "appliance/tracker/tag_pose.h"
#include "drivers/camera/camera_frame.h"

namespace mogao {

struct RoiSettings {
    bool enabled = true;  // false: every frame is searched whole with `detector` (the baseline)
    // Window = bounding box of the predicted and last corners, grown on every side by this many
    // times the tag's longer side (>= min_margin_px). (0, 5].
    double margin = 0.5;
    double min_margin_px = 16.0;  // [0, 1000]
    // A whole-frame search every N frames even while the window finds the tag; 0 = only when lost.
    // [0, 100000].
    int full_search_every = 15;
    // Settings of the whole-frame search (the rest as TrackerConfig::detector): decimation 2 with a
    // 0.8 px blur costs about half of full resolution and still finds tags of ~20 px on synthetic
    // frames (docs/tracking.md); the tag is then followed at full resolution in the window.
    float search_decimation = 2.0f;  // [1, 8]
    float search_blur_sigma = 0.8f;  // [-5, 5]
    // Window decimation from the tag's apparent size (above). window_tag_px: the shortest side
    // (pixels) the decimated tag keeps, [4, 1000]; 0 = the window at the detector's settings
    // (full resolution by default). window_max_decimation: [1, 8]. window_blur_sigma: the blur
    // (pixels of the decimated image) when decimating, [-5, 5].
    double window_tag_px = 40.0;
    int window_max_decimation = 4;
    float window_blur_sigma = 0.8f;
    // Idle (no tag seen for idle_after_s, or none yet since the first frame): the whole frame is
    // searched at most once per idle_search_period_s (frame timestamps) instead of in every frame,
    // so an empty hall costs a fraction of the search (1/3 at 30 fps with 0.1 s) and a tag coming
    // into view is found within one period. A tag lost for less than idle_after_s (a hand passing
    // over it) is still searched for in every frame. 0 = every frame. Both [0, 3600]; a frame
    // stamped before the last search (a replay starting again) is searched.
    double idle_after_s = 1.0;
    double idle_search_period_s = 0.1;
};

struct TrackerConfig {
    // The detector: every frame's without ROI; with ROI the window's for small tags, and the rest
    // of the settings (family, refine_edges, ...) of every search. Its up-sampled search for tiny
    // tags (upsample_pass_factor) is never run by the tracker (tag_tracker.cpp).
    DetectorSettings detector;
    RoiSettings roi;
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
    bool ambiguous = false;    // the IPPE choice was made by continuity
    TagDetection detection;    // full-frame pixels
    bool from_window = false;  // found by the region-of-interest search (else by a whole-frame one)
};

class TagTracker {
public:
    // Throws std::invalid_argument for bad settings (detector, roi), intrinsics or tag size.
    explicit TagTracker(const TrackerConfig& config);

    // Throws std::invalid_argument if the frame's size differs from config.camera's.
    [[nodiscard]] TrackedTag track(const CameraFrame& frame);

    [[nodiscard]] const TrackerConfig& config() const { return config_; }

    // Whole-frame searches so far (the first frame, losses and the cadence): for tests and benches.
    [[nodiscard]] long full_searches() const { return full_searches_; }
    // The quad decimation of the last window search (0: none ran in the last frame).
    [[nodiscard]] int last_window_decimation() const { return last_window_decimation_; }

private:
    const TagDetection* pick(const std::vector<TagDetection>& detections) const;
    [[nodiscard]] bool idle_throttled(std::int64_t timestamp_ns) const;
    std::vector<TagDetection> detect_in_window(const GrayImage& image, std::int64_t timestamp_ns);

    TrackerConfig config_;
    // One detector for the window and the whole-frame search (set_quad_search switches between
    // their decimations): one set of decode tables.
    TagDetector detector_;
    PoseDisambiguator disambiguator_;
    // The followed tag's last two sightings (ROI prediction); cleared when it is lost.
    int followed_id_ = -1;
    int sightings_ = 0;
    std::array<Eigen::Vector2d, 4> last_corners_{};
    std::array<Eigen::Vector2d, 4> velocity_px_s_{};
    std::int64_t last_corners_ns_ = 0;
    int frames_since_search_ = 0;
    long full_searches_ = 0;
    std::int64_t first_search_ns_ = 0;  // timestamps of the first and the last whole-frame search
    std::int64_t last_search_ns_ = 0;
    int last_window_decimation_ = 0;
    GrayImage window_;  // reused crop buffer
    std::int64_t last_seen_ns_ = 0;
    bool seen_ = false;
};

}  // namespace mogao
