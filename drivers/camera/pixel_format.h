// SPDX-License-Identifier: Apache-2.0
// Conversions from the V4L2 wire formats the capture accepts to GrayImage, and their names.
//
// Layouts (V4L2 uAPI, "Image Formats"):
//   GREY  one byte per pixel, Y' 0..255; rows are `bytes_per_line` apart (>= width)
//   YUYV  4:2:2 packed, Y0 U0 Y1 V0 per two pixels; rows are `bytes_per_line` apart (>= 2 * width);
//         the grey image is the Y' bytes as they are (limited-range Y' 16..235 is not expanded:
//         AprilTag thresholds locally, so a range scale changes nothing it measures)
//   MJPEG see mjpeg_decoder.h
// Errors (common/result.h): EINVAL for a width/height outside [1, kMaxCaptureDimension], a
// stride below the row size, or a buffer shorter than the image it must hold; the message names
// the format, the value and the limit.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "drivers/camera/camera_frame.h"
#include "common/result.h"

namespace mogao {

// Largest width or height accepted from a driver or file: far above any tracking camera, small
// enough that a corrupt header cannot make the appliance allocate gigabytes.
inline constexpr int kMaxCaptureDimension = 8192;

// "GREY", "YUYV", "MJPG", "file".
[[nodiscard]] std::string pixel_format_name(CaptureFormat format);

// A V4L2 fourcc as four characters ("YUYV"); non-printable bytes become '?'.
[[nodiscard]] std::string fourcc_name(std::uint32_t fourcc);

// Copies a GREY buffer into `out` (resized to width x height).
[[nodiscard]] Status grey_from_grey(std::span<const std::uint8_t> data, int width, int height, int bytes_per_line,
                                    GrayImage& out);

// Extracts Y' from a YUYV buffer into `out` (resized to width x height). Width must be even.
[[nodiscard]] Status grey_from_yuyv(std::span<const std::uint8_t> data, int width, int height, int bytes_per_line,
                                    GrayImage& out);

}  // namespace mogao
