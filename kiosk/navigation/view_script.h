// SPDX-License-Identifier: Apache-2.0
// ViewScript: the scripted visitor ([navigation] source = "path"; tracking: kiosk/navigation/tracking_thread.h). It
// walks a camera path (common/camera_path.h: "walk", "orbit" or a JSON path file) of `path_frames` poses and starts
// over at the end, turning each pose into the ViewRequest the kiosk submits to the farm: the cylindrical-screen camera,
// the content size and the quality knobs of the configuration. One request per display tick; the LinkClient assigns its
// id and stamps request_time_ns.
#pragma once

#include <cstdint>
#include <vector>

#include "common/view_request.h"
#include "kiosk/config/kiosk_config.h"

namespace mogao {

// The request every pose is filled into: the [screen] camera (CylinderScreen: its eye at the
// configured eye height), [quality]'s content size and knobs. Pose, frame_id and request_time_ns are
// left for later.
[[nodiscard]] ViewRequest make_view_template(const CylinderScreen& screen, const QualityConfig& quality);

class ViewScript {
public:
    // Throws std::invalid_argument for no poses.
    ViewScript(std::vector<ViewerPose> poses, ViewRequest request_template);

    // The next pose's request (cycling), request_time_ns = 0 (stamped on submit).
    [[nodiscard]] ViewRequest next();

    [[nodiscard]] std::size_t size() const { return poses_.size(); }

private:
    std::vector<ViewerPose> poses_;
    ViewRequest template_;
    std::size_t next_ = 0;
};

// make_camera_path(navigation.path, viewer from [navigation], path_frames), each pose filled into
// `request_template` (make_view_template). Throws PathError naming the path file and field.
[[nodiscard]] ViewScript make_view_script(const NavigationConfig& navigation, ViewRequest request_template);

}  // namespace mogao
