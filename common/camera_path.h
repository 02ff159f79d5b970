// SPDX-License-Identifier: Apache-2.0
// Scripted viewer paths for headless tours: the farm's stand-in for the appliance's navigation
// until live view requests arrive over the link.
//
// Every path keeps the eye at the scene's fixed eye height above the floor position (the seed
// paper's navigation: eye height fixed, the visitor walks and turns). Positions in world metres,
// yaw/pitch in degrees as in view/view_request.h.
//
// Path files (JSON): { "keyframes": [ { "position": [x, y, z], "yaw_deg": a, "pitch_deg": b }, ... ] }
// where position is the floor point under the eye (y is the floor height). Frames are spread
// evenly over the path's length (floor distance + 1 m per 90 degrees of turn, i.e. a constant
// pace) and interpolated linearly between keyframes (yaw along the shorter arc).
// Errors: PathError naming the file/field and the rule broken.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/view_request.h"
#include "common/viewer.h"

namespace mogao {

struct PathError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// "walk": from the viewer's start toward the room's centre, then around it looking at the centre.
// "orbit": a full circle around the centre at the start's distance, looking at the centre.
// Anything else is read as a path file.
[[nodiscard]] std::vector<ViewerPose> make_camera_path(const std::string& name_or_file, const Viewer& viewer,
                                                       int frames);

[[nodiscard]] std::vector<ViewerPose> read_path_file(const std::filesystem::path& file, const Viewer& viewer,
                                                     int frames);

}  // namespace mogao
