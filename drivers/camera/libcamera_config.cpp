// SPDX-License-Identifier: Apache-2.0
// The pure helpers of libcamera_capture.h: built with and without libcamera.
#include <algorithm>

#include "drivers/camera/libcamera_capture.h"
#include "drivers/camera/pixel_format.h"

namespace mogao {

Status check_libcamera_config(const LibcameraConfig& c) {
    const auto bad = [](const std::string& what) { return make_error(EINVAL, "LibcameraConfig: " + what); };
    if (c.width < 1 || c.width > kMaxCaptureDimension || c.height < 1 || c.height > kMaxCaptureDimension) {
        return bad("width x height " + std::to_string(c.width) + "x" + std::to_string(c.height) + " outside [1, " +
                   std::to_string(kMaxCaptureDimension) + "]");
    }
    if (c.formats.empty()) return bad("formats is empty");
    for (CaptureFormat f : c.formats) {
        if (libcamera_fourcc(f) == 0) return bad("formats: image_file is not a capture format");
    }
    if (c.buffer_count < 2 || c.buffer_count > 4) {
        return bad("buffer_count " + std::to_string(c.buffer_count) + " outside [2, 4]");
    }
    if (c.timeout_ms < 1 || c.timeout_ms > 60000) {
        return bad("timeout_ms " + std::to_string(c.timeout_ms) + " outside [1, 60000]");
    }
    return {};
}

std::optional<CaptureFormat> choose_libcamera_format(const std::vector<CaptureFormat>& preference,
                                                     const std::vector<std::uint32_t>& offered, bool colour) {
    for (CaptureFormat f : preference) {
        if (colour && f == CaptureFormat::grey) continue;  // R8 has no colour
        const std::uint32_t fourcc = libcamera_fourcc(f);
        if (fourcc != 0 && std::find(offered.begin(), offered.end(), fourcc) != offered.end()) return f;
    }
    return std::nullopt;
}

std::int64_t libcamera_frame_timestamp_ns(std::optional<std::int64_t> sensor_timestamp_ns,
                                          std::uint64_t buffer_timestamp_ns) noexcept {
    if (sensor_timestamp_ns && *sensor_timestamp_ns > 0) return *sensor_timestamp_ns;
    return static_cast<std::int64_t>(buffer_timestamp_ns);
}

}  // namespace mogao
