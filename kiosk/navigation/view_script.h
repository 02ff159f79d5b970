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

// The request every scripted pose is filled into: CylinderScreen camera (eye at the configured
// eye height), content size, quality. Pose, frame_id and request_time_ns are left for later.
[[nodiscard]] ViewRequest make_view_template(const KioskConfig& config);

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

// make_camera_path(config.navigation.path, viewer from [navigation], path_frames). Throws PathError
// naming the path file and field.
[[nodiscard]] ViewScript make_view_script(const KioskConfig& config);

}  // namespace mogao
