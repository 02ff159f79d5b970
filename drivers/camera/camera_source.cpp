// SPDX-License-Identifier: Apache-2.0
#include "drivers/camera/camera_source.h"

#include <cerrno>

#include "drivers/camera/libcamera_capture.h"
#include "drivers/camera/replay_source.h"
#include "drivers/camera/v4l2_capture.h"

namespace mogao {

bool parse_camera_source(std::string_view text, CameraSourceSpec& out, std::string* why) {
    const auto set_why = [why](std::string message) {
        if (why != nullptr) *why = std::move(message);
        return false;
    };
    constexpr std::string_view replay = "replay:";
    constexpr std::string_view v4l2 = "v4l2:";
    if (text.starts_with(replay)) {
        const std::string_view folder = text.substr(replay.size());
        if (folder.empty()) return set_why("'replay:' needs a folder (\"replay:<folder>\")");
        out.kind = CameraSourceSpec::Kind::replay;
        out.folder = std::filesystem::path(std::string(folder));
        return true;
    }
    if (text.starts_with(v4l2)) {
        const std::string_view device = text.substr(v4l2.size());
        if (device.empty()) return set_why("'v4l2:' needs a device (\"v4l2:/dev/videoN\")");
        out.kind = CameraSourceSpec::Kind::v4l2;
        out.device = std::string(device);
        return true;
    }
    constexpr std::string_view libcamera = "libcamera:";
    if (text.starts_with(libcamera)) {
        out.kind = CameraSourceSpec::Kind::libcamera;
        out.camera_id = std::string(text.substr(libcamera.size()));  // empty: the first camera
        return true;
    }
    return set_why("'" + std::string(text) +
                   "' is none of \"replay:<folder>\", \"v4l2:/dev/videoN\", \"libcamera:[<camera id>]\"");
}

Result<std::unique_ptr<FrameSource>> open_camera_source(const CameraSourceSpec& spec) {
    if (spec.kind == CameraSourceSpec::Kind::replay) {
        auto replay = ReplaySource::open({spec.folder, spec.replay_fps, spec.loop});
        if (!replay) return replay.error();
        return std::unique_ptr<FrameSource>(std::move(replay).value());
    }
    const auto check_size = [&spec](ImageSize got, const std::string& name) -> Status {
        if (got.width == spec.width && got.height == spec.height) return {};
        return make_error(EINVAL, name + ": delivers " + std::to_string(got.width) + "x" + std::to_string(got.height) +
                                      ", not the calibrated " + std::to_string(spec.width) + "x" +
                                      std::to_string(spec.height));
    };
    if (spec.kind == CameraSourceSpec::Kind::libcamera) {
        LibcameraConfig config;
        config.camera_id = spec.camera_id;
        config.width = spec.width;
        config.height = spec.height;
        config.timeout_ms = spec.timeout_ms;
        config.colour = spec.colour;
        config.controls = spec.controls;
        auto camera = LibcameraCapture::open(config);
        if (!camera) return camera.error();
        if (Status s = check_size((*camera)->size(), "libcamera:" + spec.camera_id); !s) return s.error();
        return std::unique_ptr<FrameSource>(std::move(camera).value());
    }
    V4l2Config config;
    config.device = spec.device;
    config.width = spec.width;
    config.height = spec.height;
    config.frames_per_second = spec.fps;
    config.timeout_ms = spec.timeout_ms;
    config.colour = spec.colour;
    config.controls = spec.controls;
    auto camera = V4l2Capture::open(config);
    if (!camera) return camera.error();
    if (Status s = check_size((*camera)->size(), spec.device); !s) return s.error();
    return std::unique_ptr<FrameSource>(std::move(camera).value());
}

}  // namespace mogao
