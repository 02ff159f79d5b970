// SPDX-License-Identifier: Apache-2.0
// LibcameraCapture: a camera streamed through libcamera (0.0.x API, Debian 12 ships 0.0.3), the
// second FrameSource backend beside V4l2Capture. Built only with MOGAO_LIBCAMERA (CMake option:
// AUTO = if pkg-config finds libcamera, ON = required, OFF); without it open() returns ENOTSUP
// "built without libcamera" and libcamera_built_in() is false. This header never includes
// libcamera's (they stay private to libcamera_capture.cpp, as SYSTEM includes).
//
// Pipeline: CameraManager::start, the configured camera (or the first one) acquired, one
// Viewfinder stream in the first format of `formats` the camera offers (GREY = libcamera R8,
// YUYV, NV12/NV21/YUV420/YVU420, packed RGB = BGR888/RGB888, MJPEG), FrameBufferAllocator
// buffers (2-4 asked; the pipeline may adjust), one Request per buffer, Camera::start, all
// requests queued. Each buffer's plane is mmapped read-only from its dmabuf fd (MappedBuffer;
// libcamera's MappedFrameBuffer is internal).
//
// Threading: libcamera emits requestCompleted on its own thread. The slot only appends the
// request to a list under a mutex (capacity reserved at open, so it never allocates or throws)
// and notifies a condition variable. next_frame() (the caller's thread) waits for it, takes every
// completed request, re-queues all but the newest at once (CameraFrame::skipped counts them and
// failed frames), converts the newest to grey, re-queues it and returns the copy. No CameraFrame
// aliases a libcamera buffer. Camera::queueRequest is thread-safe in libcamera.
//
// Timestamps: controls::SensorTimestamp from the request metadata when the pipeline reports it,
// else the buffer's FrameMetadata::timestamp; both are the V4L2 buffer timestamp on uvcvideo and
// simple pipelines (CLOCK_MONOTONIC). libcamera documents SensorTimestamp as CLOCK_BOOTTIME, which
// equals CLOCK_MONOTONIC unless the machine has been suspended; CameraFrame::clock is
// kernel_monotonic either way.
//
// One at a time: libcamera 0.0.x aborts the process (Fatal log) if a second CameraManager is
// created, so a second open() while one LibcameraCapture lives returns EBUSY.
//
// Errors (common/result.h), naming the camera and the call: ENODEV (no camera, unknown id,
// camera disconnected), EBUSY (acquire refused, or another LibcameraCapture open), ENOTSUP (none of
// the wanted formats; the message lists the camera's; or built without libcamera), EINVAL (config
// field and limit, or a configuration the pipeline rejects), ETIMEDOUT / EBADMSG from next_frame();
// libcamera's negative errno returns become positive codes.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/pixel_rect.h"
#include "drivers/camera/camera_controls.h"
#include "drivers/camera/frame_source.h"

namespace mogao {

struct LibcameraConfig {
    std::string camera_id;  // libcamera's Camera::id(); empty = the first camera CameraManager lists
    int width = 800;        // requested; the pipeline may adjust it (see size())
    int height = 600;
    // Formats to try, in order of preference (GREY needs no conversion, MJPEG the most CPU).
    // Packed RGB (rgb24/bgr24) is what libcamera's vimc pipeline (the kernel's virtual media
    // controller camera) offers.
    std::vector<CaptureFormat> formats{CaptureFormat::grey,  CaptureFormat::yuyv,   CaptureFormat::nv12,
                                       CaptureFormat::nv21,  CaptureFormat::yuv420, CaptureFormat::yvu420,
                                       CaptureFormat::rgb24, CaptureFormat::bgr24,  CaptureFormat::mjpeg};
    bool colour = false;      // also deliver CameraFrame::colour (R'G'B'); GREY (R8) is then not used
    CameraControls controls;  // applied when the camera starts (camera_controls.h)
    int buffer_count = 3;     // [2, 4]
    int timeout_ms = 2000;    // [1, 60000]: next_frame() gives ETIMEDOUT after this long without a frame
};

// True when this build of mogao_camera has the libcamera backend (MOGAO_HAVE_LIBCAMERA).
[[nodiscard]] bool libcamera_built_in() noexcept;

// libcamera's (DRM) fourcc for a capture format: GREY -> R8 ("R8  "), YUYV, MJPEG ("MJPG"), NV12,
// NV21, YUV420 ("YU12"), YVU420 ("YV12"), rgb24 -> BGR888 ("BG24"), bgr24 -> RGB888 ("RG24");
// 0 for image_file. Pure; the .cpp checks these against libcamera::formats at compile time.
[[nodiscard]] constexpr std::uint32_t libcamera_fourcc(CaptureFormat format) noexcept {
    constexpr auto cc = [](char a, char b, char c, char d) {
        return static_cast<std::uint32_t>(static_cast<unsigned char>(a)) |
               static_cast<std::uint32_t>(static_cast<unsigned char>(b)) << 8 |
               static_cast<std::uint32_t>(static_cast<unsigned char>(c)) << 16 |
               static_cast<std::uint32_t>(static_cast<unsigned char>(d)) << 24;
    };
    switch (format) {
        case CaptureFormat::grey:
            return cc('R', '8', ' ', ' ');
        case CaptureFormat::yuyv:
            return cc('Y', 'U', 'Y', 'V');
        case CaptureFormat::mjpeg:
            return cc('M', 'J', 'P', 'G');
        case CaptureFormat::nv12:
            return cc('N', 'V', '1', '2');
        case CaptureFormat::nv21:
            return cc('N', 'V', '2', '1');
        case CaptureFormat::yuv420:
            return cc('Y', 'U', '1', '2');
        case CaptureFormat::yvu420:
            return cc('Y', 'V', '1', '2');
        case CaptureFormat::rgb24:  // bytes R G B: DRM's BGR888 (components named from the high byte)
            return cc('B', 'G', '2', '4');
        case CaptureFormat::bgr24:
            return cc('R', 'G', '2', '4');
        case CaptureFormat::image_file:
            break;
    }
    return 0;
}

// EINVAL naming the field and its limit, or success. Pure.
[[nodiscard]] Status check_libcamera_config(const LibcameraConfig& config);

// The first of `preference` whose libcamera fourcc is in `offered` (fourccs, e.g. from
// StreamFormats::pixelformats()), or nothing. Pure.
// With `colour`, GREY is passed over (R8 has no colour).
[[nodiscard]] std::optional<CaptureFormat> choose_libcamera_format(const std::vector<CaptureFormat>& preference,
                                                                   const std::vector<std::uint32_t>& offered,
                                                                   bool colour = false);

// The frame timestamp: the request's SensorTimestamp when present and positive, else the buffer's
// metadata timestamp (ns). Pure.
[[nodiscard]] std::int64_t libcamera_frame_timestamp_ns(std::optional<std::int64_t> sensor_timestamp_ns,
                                                        std::uint64_t buffer_timestamp_ns) noexcept;

// What `mogao-camera info libcamera:[<id>]` prints: for the camera `camera_id` (empty: every
// camera libcamera lists) its id and model, the Viewfinder stream's pixel formats with their size
// ranges, and every control with its range and default (libcamera's ControlInfo text, e.g.
// "ExposureTime: [100..33000]" in microseconds). Starts and stops its own CameraManager, so it
// fails with EBUSY while a LibcameraCapture is open in this process; ENODEV when no camera (or not
// that id) is found; ENOTSUP when built without libcamera.
[[nodiscard]] Result<std::string> describe_libcamera_cameras(const std::string& camera_id);

class LibcameraCapture final : public FrameSource {
public:
    // Starts libcamera, acquires and configures the camera, allocates and maps buffers, starts
    // streaming with every request queued.
    [[nodiscard]] static Result<std::unique_ptr<LibcameraCapture>> open(const LibcameraConfig& config);
    ~LibcameraCapture() override;  // stops the camera, unmaps, frees buffers, releases, stops libcamera

    [[nodiscard]] Result<CameraFrame> next_frame() override;
    [[nodiscard]] std::string description() const override;

    [[nodiscard]] ImageSize size() const { return {width_, height_}; }
    [[nodiscard]] CaptureFormat format() const { return format_; }
    [[nodiscard]] int buffer_count() const { return buffer_count_; }
    [[nodiscard]] const std::string& camera_id() const { return camera_id_; }

private:
    struct Impl;  // libcamera objects; defined in libcamera_capture.cpp
    LibcameraCapture();

    std::unique_ptr<Impl> impl_;
    std::string camera_id_;
    CaptureFormat format_ = CaptureFormat::grey;
    int width_ = 0;
    int height_ = 0;
    int buffer_count_ = 0;
};

}  // namespace mogao
