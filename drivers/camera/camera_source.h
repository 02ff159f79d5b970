// SPDX-License-Identifier: Apache-2.0
// The camera the tracking input reads from, named by one string, and opened as a FrameSource:
//   "replay:<folder>"     a folder of images (drivers/camera/replay_source.h), e.g. the output of
//                         `mogao-tag-sequence`
//   "v4l2:/dev/videoN"    a V4L2 camera (drivers/camera/v4l2_capture.h), asked for the given size
//                         (the calibrated one: TagTracker refuses frames of another size) and rate
//   "libcamera:<id>"      a camera through libcamera (drivers/camera/libcamera_capture.h), <id> as
//                         libcamera lists it (Camera::id()); "libcamera:" alone = its first camera.
//                         Same size rule as V4L2. Without libcamera built in, opening is ENOTSUP.
// Shared by `mogao-track navigate` (track_navigate.cpp) and the kiosk's tracking thread
// (kiosk/navigation/tracking_thread.h), so both open a camera the same way.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

#include "common/result.h"
#include "drivers/camera/camera_controls.h"
#include "drivers/camera/frame_source.h"

namespace mogao {

struct CameraSourceSpec {
    enum class Kind { replay, v4l2, libcamera };
    Kind kind = Kind::replay;
    std::filesystem::path folder;  // replay
    double replay_fps = 30.0;      // replay: rate when the folder has no timestamps.txt, (0, 1000]
    bool loop = false;             // replay: start again after the last frame instead of ENODATA
    std::string device;            // v4l2: /dev/videoN
    std::string camera_id;         // libcamera: Camera::id(); empty = the first camera
    int width = 800;               // v4l2, libcamera: requested size (the driver may choose another: checked)
    int height = 600;
    int fps = 0;              // v4l2: requested rate, 0 = the driver's default
    int timeout_ms = 2000;    // v4l2, libcamera: next_frame() gives ETIMEDOUT after this long
    bool colour = false;      // v4l2, libcamera: also deliver CameraFrame::colour (camera_frame.h)
    CameraControls controls;  // v4l2, libcamera: exposure, gain, white balance (camera_controls.h)
};

// "replay:<folder>", "v4l2:<device>" or "libcamera:[<id>]" -> true and `out.kind` + folder/device/
// camera_id set (other fields untouched); false and `why` set (what is wrong, with the accepted
// forms) otherwise.
[[nodiscard]] bool parse_camera_source(std::string_view text, CameraSourceSpec& out, std::string* why);

// Opens the source. A live camera (V4L2 or libcamera) that delivers another size than asked for is
// an EINVAL error naming both sizes (the calibration would not hold).
[[nodiscard]] Result<std::unique_ptr<FrameSource>> open_camera_source(const CameraSourceSpec& spec);

}  // namespace mogao
