// SPDX-License-Identifier: Apache-2.0
// What a V4L2 camera supports, as the driver reports it (V4L2 uAPI: VIDIOC_QUERYCAP,
// VIDIOC_ENUM_FMT, VIDIOC_ENUM_FRAMESIZES, VIDIOC_ENUM_FRAMEINTERVALS, VIDIOC_QUERY_EXT_CTRL,
// VIDIOC_QUERYMENU): formats with their sizes and frame rates, and controls with their ranges and
// current values. Used by `mogao-camera list|info` (camera_main.cpp) to choose the kiosk's camera
// keys ([navigation].camera_size, camera_fps, camera_exposure_us, camera_gain, ...).
//
// Errors (common/result.h), naming the device: the errno of open; ENOTTY "not a V4L2 device";
// ENODEV for a node that cannot capture.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/result.h"

namespace mogao {

struct V4l2FrameSize {
    bool stepwise = false;  // true: [min, max] in steps; false: one discrete size (min)
    int min_width = 0, min_height = 0;
    int max_width = 0, max_height = 0;
    int step_width = 0, step_height = 0;
    std::vector<double> frame_rates;  // fps of a discrete size (at most the first 16 intervals)
};

struct V4l2FormatInfo {
    std::uint32_t fourcc = 0;
    std::string description;  // the driver's, e.g. "Y/UV 4:2:0"
    bool compressed = false;
    std::vector<V4l2FrameSize> sizes;
};

struct V4l2ControlInfo {
    std::uint32_t id = 0;
    std::string name;  // the driver's, e.g. "Exposure Time, Absolute"
    std::string type;  // "int", "bool", "menu", "int menu", "button", "int64", "class", "other"
    long long minimum = 0, maximum = 0, step = 0, default_value = 0;
    bool has_value = false;  // false for write-only, inactive-unreadable and compound controls
    long long value = 0;
    bool inactive = false;  // e.g. a manual exposure while auto exposure is on
    bool read_only = false;
    std::vector<std::string> menu;  // "index: name" of each item the driver offers
};

struct V4l2DeviceInfo {
    std::string device;
    std::string driver, card, bus;
    bool multiplanar = false;  // capture through V4L2_BUF_TYPE_VIDEO_CAPTURE_MPLANE
    std::vector<V4l2FormatInfo> formats;
    std::vector<V4l2ControlInfo> controls;
};

// Queries one device node (opened O_RDWR | O_NONBLOCK; nothing is changed).
[[nodiscard]] Result<V4l2DeviceInfo> query_v4l2_device(const std::string& device);

// Every /dev/videoN (N < 64) that opens, answers VIDIOC_QUERYCAP and can capture; formats and
// controls left empty.
[[nodiscard]] std::vector<V4l2DeviceInfo> list_v4l2_devices();

// The info as text for people (what `mogao-camera info` prints).
[[nodiscard]] std::string format_v4l2_info(const V4l2DeviceInfo& info);

}  // namespace mogao
