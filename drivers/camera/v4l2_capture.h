// SPDX-License-Identifier: Apache-2.0
// V4l2Capture: a V4L2 video-capture device streamed with memory-mapped buffers (V4L2 uAPI,
// "Streaming I/O (Memory Mapping)": VIDIOC_REQBUFS, QUERYBUF + mmap, QBUF, STREAMON, DQBUF).
//
// Always the newest frame: the device fd is non-blocking; next_frame() polls until at least one
// buffer is ready, then dequeues every ready buffer, re-queues all but the last at once and
// returns the last (CameraFrame::skipped counts the others). With 2-3 buffers the driver always has one
// to fill while the tracker works, and a slow tracker sees at most one frame of queueing delay.
//
// Formats: GREY, YUYV, NV12, NV21, YU12 (YUV420), YV12 (YVU420) and MJPEG (preference order
// configurable), converted to grey as captured and, with `colour`, to R'G'B' too with the matrix
// and range of the format's V4L2 colour fields (pixel_format.h, mjpeg_decoder.h); `colour` drops
// GREY from the preference (it has no colour). Single-planar (V4L2_BUF_TYPE_VIDEO_CAPTURE) and
// multi-planar (V4L2_BUF_TYPE_VIDEO_CAPTURE_MPLANE: NV12M, NV21M, YUV420M, YVU420M, or one-plane
// formats through the multi-planar API, as ISP drivers offer them) nodes; each plane is mapped
// separately. The frame is copied out of the mapping and the buffer goes back to the driver before
// next_frame() returns, so no CameraFrame ever aliases a kernel buffer.
//
// Controls: exposure, gain and white balance (camera_controls.h, v4l2_controls.h) are applied at
// open, before streaming starts, and again by apply_controls() at any time (e.g. lock after the
// automatic loops have settled).
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
// ENOTSUP when none of the wanted formats is offered (the message lists the device's formats), or
// a required control is missing; EINVAL for a control value outside the device's range;
// EINVAL for a bad config (names the field and its limit); ETIMEDOUT / EBADMSG from next_frame().
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "common/mapped_buffer.h"
#include "common/pixel_rect.h"
#include "common/unique_fd.h"
#include "drivers/camera/camera_controls.h"
#include "drivers/camera/frame_source.h"
#include "drivers/camera/mjpeg_decoder.h"
#include "drivers/camera/pixel_format.h"
#include "drivers/camera/v4l2_controls.h"

namespace mogao {

struct V4l2Config {
    std::string device = "/dev/video0";
    int width = 800;  // requested; the driver may pick the nearest size it supports (see size())
    int height = 600;
    // Formats to try, in order of preference (GREY needs no conversion, MJPEG the most CPU).
    std::vector<CaptureFormat> formats{CaptureFormat::grey, CaptureFormat::yuyv,   CaptureFormat::nv12,
                                       CaptureFormat::nv21, CaptureFormat::yuv420, CaptureFormat::yvu420,
                                       CaptureFormat::mjpeg};
    bool colour = false;        // also deliver CameraFrame::colour (R'G'B'); GREY is then not used
    CameraControls controls;    // applied at open (default: every setting left as the device has it)
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
    // VIDIOC_QUERYCAP's driver name ("vivid", "uvcvideo").
    [[nodiscard]] const std::string& driver() const { return driver_; }
    [[nodiscard]] bool multiplanar() const { return multiplanar_; }
    [[nodiscard]] int plane_count() const { return plane_count_; }  // memory planes per buffer
    [[nodiscard]] YcbcrEncoding encoding() const { return encoding_; }

    // Applies exposure / gain / white balance now (see camera_controls.h for the errors).
    [[nodiscard]] Status apply_controls(const CameraControls& controls);
    // The current control values (camera_controls.h units); nullopt where the device lacks one.
    [[nodiscard]] CameraControlValues control_values() const;

private:
    V4l2Capture() = default;
    Status negotiate_format(const V4l2Config& config);
    Status start_streaming(const V4l2Config& config);
    Status requeue(std::uint32_t index);
    Status map_buffer(std::uint32_t index);
    Status convert(std::uint32_t index, const std::uint32_t* bytes_used, const std::uint32_t* data_offset,
                   CameraFrame& frame);

    // Declaration order is destruction order in reverse: buffers are unmapped before the fd closes.
    UniqueFd fd_;
    std::vector<std::vector<MappedBuffer>> buffers_;  // [buffer][plane]
    std::vector<int> plane_bytes_per_line_;           // per memory plane
    std::unique_ptr<MjpegDecoder> mjpeg_;             // only for MJPEG
    std::string device_;
    std::string driver_;
    CaptureFormat format_ = CaptureFormat::grey;
    int width_ = 0;
    int height_ = 0;
    int bytes_per_line_ = 0;
    int timeout_ms_ = 2000;
    bool streaming_ = false;
    bool multiplanar_ = false;
    bool colour_ = false;
    int plane_count_ = 1;
    std::uint32_t buf_type_ = 1;  // V4L2_BUF_TYPE_VIDEO_CAPTURE or _MPLANE
    YcbcrEncoding encoding_;
    std::string skipped_controls_;  // settings the device lacks (not required), for description()
};

}  // namespace mogao
