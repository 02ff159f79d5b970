// SPDX-License-Identifier: Apache-2.0
// V4l2Capture: a V4L2 video-capture device streamed with memory-mapped buffers (V4L2 uAPI,
// "Streaming I/O (Memory Mapping)": VIDIOC_REQBUFS, QUERYBUF + mmap, QBUF, STREAMON, DQBUF).
//
// Always the newest frame: the device fd is non-blocking; next_frame() polls until at least one
// buffer is ready, then dequeues every ready buffer, re-queues all but the last at once and
// returns the last (CameraFrame::skipped counts the others). With 2-3 buffers the driver always has one
// to fill while the tracker works, and a slow tracker sees at most one frame of queueing delay.
//
// Formats: GREY, YUYV and MJPEG (preference order configurable), converted to grey as captured
// (pixel_format.h, mjpeg_decoder.h). The frame is copied out of the mapping and the buffer goes
// back to the driver before next_frame() returns, so no CameraFrame ever aliases a kernel buffer.
//
// Timestamps: the buffer's kernel timestamp when the driver sets V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC
// (CLOCK_MONOTONIC, ns), else CLOCK_MONOTONIC read at dequeue (CameraFrame::clock says which).
//
// Ownership: the device fd is a UniqueFd (O_RDWR | O_NONBLOCK | O_CLOEXEC); each buffer mapping
// is a MappedBuffer. The destructor stops streaming (VIDIOC_STREAMOFF), then the mappings are
// unmapped and the fd closed, which frees the driver's buffers.
//
// Errors (common/result.h), each naming the device and the call: ENOENT/EACCES/EBUSY from open;
// ENOTTY "not a V4L2 device" (VIDIOC_QUERYCAP refused); ENODEV when it cannot capture or stream;
// ENOTSUP when none of the wanted formats is offered (the message lists the device's formats);
// EINVAL for a bad config (names the field and its limit); ETIMEDOUT / EBADMSG from next_frame().
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "drivers/camera/frame_source.h"
#include "drivers/camera/mapped_buffer.h"
#include "drivers/camera/mjpeg_decoder.h"
#include "common/unique_fd.h"
#include "common/pixel_rect.h"

namespace mogao {

struct V4l2Config {
    std::string device = "/dev/video0";
    int width = 800;  // requested; the driver may pick the nearest size it supports (see size())
    int height = 600;
    // Formats to try, in order of preference (GREY needs no conversion, MJPEG the most CPU).
    std::vector<CaptureFormat> formats{CaptureFormat::grey, CaptureFormat::yuyv, CaptureFormat::mjpeg};
    int buffer_count = 3;       // [2, 4]: 2-3 keeps latency at most one frame (see above)
    int frames_per_second = 0;  // 0 = the driver's default; else VIDIOC_S_PARM (best effort)
    int timeout_ms = 2000;      // [1, 60000]: next_frame() gives ETIMEDOUT after this long without a frame
};

class V4l2Capture final : public FrameSource {
public:
    // Opens, negotiates format and buffers, and starts streaming.
    [[nodiscard]] static Result<std::unique_ptr<V4l2Capture>> open(const V4l2Config& config);
    ~V4l2Capture() override;

    [[nodiscard]] Result<CameraFrame> next_frame() override;
    [[nodiscard]] std::string description() const override;

    [[nodiscard]] ImageSize size() const { return {width_, height_}; }
    [[nodiscard]] CaptureFormat format() const { return format_; }
    [[nodiscard]] int buffer_count() const { return static_cast<int>(buffers_.size()); }
    [[nodiscard]] const std::string& driver() const {
        return driver_;
    }  // VIDIOC_QUERYCAP's driver name ("vivid", "uvcvideo")

private:
    V4l2Capture() = default;
    Status negotiate_format(const V4l2Config& config);
    Status start_streaming(const V4l2Config& config);
    Status requeue(std::uint32_t index);
    Status convert(std::uint32_t index, std::uint32_t bytes_used, GrayImage& out);

    // Declaration order is destruction order in reverse: buffers are unmapped before the fd closes.
    UniqueFd fd_;
    std::vector<MappedBuffer> buffers_;
    std::unique_ptr<MjpegDecoder> mjpeg_;  // only for MJPEG
    std::string device_;
    std::string driver_;
    CaptureFormat format_ = CaptureFormat::grey;
    int width_ = 0;
    int height_ = 0;
    int bytes_per_line_ = 0;
    int timeout_ms_ = 2000;
    bool streaming_ = false;
};

}  // namespace mogao
