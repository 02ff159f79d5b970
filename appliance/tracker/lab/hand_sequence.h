// SPDX-License-Identifier: Apache-2.0
// A replayed camera sequence of a hand-held tag: known poses over time rendered to a folder of
// PNGs that ReplaySource (drivers/camera/replay_source.h) plays back, so the tracker, the
// navigation and the main demo can be driven and checked without a camera.
//
// The script (times for the default 12 s; scaled to `seconds`): rest until 1.5 s; turn the tag
// left to yaw +25 deg by 3.0 s, hold to 4.5, back to 0 by 5.5; push it 12 cm toward the camera
// between 6.0 and 7.0, hold to 8.0, back by 8.8; a fast turn right to -30 deg between 9.0 and
// 9.4, hold to 10.2, back by 10.6; the tag leaves the view from 11.0 to 11.6; rest to the end.
// Segments ease in and out (smoothstep). On top: physiological hand tremor (8-12 Hz, ~0.3 deg,
// ~0.4 mm), a slow drift, a constant roll of 3 deg, motion blur from the motion during the
// exposure, sensor noise, and a cluttered background (the same in every frame). Angles and axes
// as tag_pose_facing_camera (synthetic_view.h).
//
// Folder contents: frame-00000.png ... (8-bit grey), timestamps.txt (ns, one per frame),
// camera.json (the intrinsics, camera_intrinsics.h), truth.json:
//   {"tag": {"family", "id", "size_m"}, "frames_per_second",
//    "frames": [{"file", "time_ns", "visible", "yaw_deg", "pitch_deg", "distance_m", "x_m",
//                "rotation": [r00, r01, ..., r22] (row-major, tag -> camera), "translation_m": [x, y, z]}]}
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "appliance/tracker/camera_intrinsics.h"
#include "appliance/tracker/lab/synthetic_view.h"
#include "appliance/tracker/tag_pose.h"

namespace mogao {

struct HandSequenceSpec {
    double seconds = 12.0;            // (0, 600]
    double frames_per_second = 30.0;  // (0, 240]
    std::string family = "tag36h11";
    int tag_id = 0;
    double tag_size_m = 0.10;
    CameraIntrinsics camera = ideal_camera();
    double rest_distance_m = 0.5;  // tag centre to camera at rest, (0.05, 10]
    double noise_sigma = 2.0;      // grey levels
    double exposure_s = 0.008;     // motion blur: the tag's image motion during this time, [0, 0.1]
    std::uint64_t seed = 1;
};

struct HandFrame {
    std::int64_t time_ns = 0;
    bool visible = true;
    double yaw_deg = 0.0;  // the scripted values incl. tremor, as given to tag_pose_facing_camera
    double pitch_deg = 0.0;
    double roll_deg = 0.0;
    double distance_m = 0.0;
    double x_m = 0.0;
    double y_m = 0.0;
    TagPose pose;
};

// The scripted pose at time t (seconds from the start). Pure; throws std::invalid_argument for a
// bad spec.
[[nodiscard]] HandFrame hand_frame_at(double t_s, const HandSequenceSpec& spec);

// Every frame's truth: frame i at i / frames_per_second.
[[nodiscard]] std::vector<HandFrame> hand_trajectory(const HandSequenceSpec& spec);

// Renders the sequence into `folder` (created if missing). Throws std::invalid_argument for a bad
// spec, std::runtime_error naming the file if one cannot be written.
void write_hand_sequence(const std::filesystem::path& folder, const HandSequenceSpec& spec);

}  // namespace mogao
