// SPDX-License-Identifier: Apache-2.0
// The subcommands of mogao-track (track_main.cpp parses the command line with CLI11 and calls
// one of these). Each returns the process exit code: 0 success, 1 the job failed (an image could
// not be read, no board found, ...); bad command lines exit 2 in track_main.cpp.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "appliance/tracker/detector_settings.h"
#include "appliance/tracker/tag_tracker.h"

namespace mogao::track {

struct DetectOptions {
    std::vector<std::filesystem::path> images;
    DetectorSettings detector;
    bool json = false;
};
// Prints every detection of every image: id and four corners (AprilTag order, pixel centres at
// +0.5; docs/tracking.md), as text or as one JSON array.
int detect(const DetectOptions& options);

struct SequenceOptions {
    std::filesystem::path out;
    double seconds = 12.0;
    double fps = 30.0;
    std::string family = "tag36h11";
    int id = 0;
    double tag_size_mm = 100.0;
    int width = 800;
    int height = 600;
    double focal_px = 700.0;
    double noise = 2.0;
    unsigned long long seed = 1;
};
int make_sequence(const SequenceOptions& options);

struct TagImageOptions {
    int id = 0;
    std::string family = "tag36h11";
    int pixels_per_cell = 40;
    int margin_cells = 1;  // extra white around the tag's own border, for cutting
    std::filesystem::path out;
};
int make_tag(const TagImageOptions& options);

struct NavigateOptions {
    std::filesystem::path replay;  // a replay folder, or
    std::string
        device;  // --camera: /dev/videoN, v4l2:..., libcamera:[<id>] (then `camera` is required; runs until killed)
    std::filesystem::path camera;  // --camera-calibration; default: <replay>/camera.json
    double tag_size_mm = 100.0;
    int id = -1;
    double display_hz = 60.0;
    double fps = 30.0;          // replay rate when the folder has no timestamps.txt
    std::filesystem::path out;  // JSON lines of ViewerPose; default stdout
    DetectorSettings detector;
    bool roi = true;  // RoiSettings::enabled (false: every frame searched whole, `detector`)
    double window_tag_px = RoiSettings{}.window_tag_px;  // RoiSettings::window_tag_px (0: window at `detector`)
};
// Frames (replay folder or V4L2 camera) -> TagTracker -> Navigator -> ViewerPose JSON lines.
int navigate(const NavigateOptions& options);

}  // namespace mogao::track
