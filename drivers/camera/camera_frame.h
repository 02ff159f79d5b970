// SPDX-License-Identifier: Apache-2.0
// What every capture source delivers: one 8-bit grey (luma) image, optionally a colour image,
// and when it was taken.
//
// The tracker only needs luma (AprilTag detects on grey), so every source converts to grey as it
// captures: GREY is copied, YUYV and the 4:2:0 formats keep their Y' bytes, MJPEG is decoded
// straight to grey by TurboJPEG (cheaper than decoding colour and converting). Colour is converted
// only when the source was opened with `colour = true` (camera-based projector calibration); it is
// then R'G'B' as the camera encodes it (gamma-encoded, no linearisation, no colour management) and
// `colour` has the same size as `image`. Without it, `colour` stays empty and costs nothing.
//
// Pixels: row-major, top row first, no padding between rows. Pixel (x, y) covers [x, x+1) x
// [y, y+1); its centre is at (x + 0.5, y + 0.5) (docs/architecture.md). AprilTag 3.3 reports
// corners in this convention too; OpenCV (and so camera intrinsics) puts the top-left pixel's
// centre at (0, 0). docs/tracking.md says where each is used.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "common/image.h"

namespace mogao {

struct GrayImage {
    int width = 0;                     // pixels
    int height = 0;                    // pixels
    std::vector<std::uint8_t> pixels;  // width * height values, 0 = black, 255 = white

    GrayImage() = default;
    GrayImage(int w, int h, std::uint8_t fill = 0)
        : width(w), height(h), pixels(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), fill) {}

    [[nodiscard]] bool valid() const {
        return width > 0 && height > 0 &&
               pixels.size() == static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    }
    [[nodiscard]] std::uint8_t at(int x, int y) const {
        return pixels[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)];
    }
};

// Where a frame's timestamp comes from.
enum class TimestampSource {
    kernel_monotonic,   // the driver's buffer timestamp, CLOCK_MONOTONIC (V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC):
                        // when the first byte of the frame was captured (V4L2 "start of exposure" is
                        // driver-specific; uvcvideo stamps the start of the frame)
    dequeue_monotonic,  // the driver gave no monotonic stamp: CLOCK_MONOTONIC read when the buffer was dequeued
    replay,             // from the replay folder's timestamps.txt, or index / fps
};

// The pixel format the frame had on the wire, before conversion (pixel_format.h has the layouts).
// nv12/nv21/yuv420/yvu420 are 4:2:0 and cover both the one-buffer V4L2 formats (NV12, NV21, YU12,
// YV12) and their multi-plane variants (NV12M, NV21M, YUV420M, YVU420M).
// rgb24/bgr24 are packed 8-bit R'G'B', 3 bytes per pixel in memory order R G B (V4L2 RGB3, libcamera
// BGR888) or B G R (V4L2 BGR3, libcamera RGB888: DRM names list the components from the high byte).
enum class CaptureFormat { grey, yuyv, mjpeg, image_file, nv12, nv21, yuv420, yvu420, rgb24, bgr24 };

struct CameraFrame {
    GrayImage image;
    std::int64_t timestamp_ns = 0;  // see `clock`; only differences between frames of one source are meaningful
    TimestampSource clock = TimestampSource::replay;
    std::uint64_t sequence = 0;  // driver's frame counter (V4L2 sequence) or index in the replay
    std::uint32_t skipped = 0;   // older frames that were ready but dropped to deliver this, the newest
    CaptureFormat format = CaptureFormat::grey;
    std::optional<Rgb8Image> colour;  // only when the source was opened with colour = true
};

}  // namespace mogao
