// SPDX-License-Identifier: Apache-2.0
// The one interface the tracker reads frames from: a V4L2 camera (v4l2_capture.h) or a folder of
// images (replay_source.h), and libcamera where built with it (libcamera_capture.h, MOGAO_LIBCAMERA).
//
// Errors follow common/result.h: next_frame() never throws. Codes a caller can branch on:
//   ENODATA    a finite source (replay without loop) has no more frames
//   ETIMEDOUT  no frame arrived within the source's timeout (camera unplugged, stalled stream)
//   EBADMSG    one frame could not be decoded (corrupt MJPEG, unreadable image); the next may work
//   other      errno of the failed system call (ENODEV after an unplug, EIO, ...)
#pragma once

#include <cstdint>
#include <optional>

#include <string>

#include "common/result.h"
#include "drivers/camera/camera_frame.h"

namespace mogao {

class FrameSource {
public:
    virtual ~FrameSource() = default;
    FrameSource() = default;
    FrameSource(const FrameSource&) = delete;
    FrameSource& operator=(const FrameSource&) = delete;

    // Blocks until a frame is available and returns the newest one (a camera drops older frames
    // that queued up while the caller was busy, and says how many in CameraFrame::skipped).
    [[nodiscard]] virtual Result<CameraFrame> next_frame() = 0;

    // When the frame that next_frame() would return next was (or will be) captured, on the clock of
    // CameraFrame::timestamp_ns -- known only to sources that play recorded frames (a replay);
    // nullopt for live cameras and after a finite source's last frame. A pacing caller uses it to
    // drop a frame whose successor is already due, as a live camera would have overwritten it.
    [[nodiscard]] virtual std::optional<std::int64_t> next_capture_time_ns() const { return std::nullopt; }

    // Drops, WITHOUT decoding them, the frames next_frame() would return next whose successor was
    // captured at or before `now_ns` (CameraFrame::timestamp_ns's clock): the frames a pacing
    // caller would drop anyway, skipped before the decoding that costs a replay several times the
    // tracking. Returns how many were dropped; 0 for sources that cannot tell (live cameras, which
    // drop stale frames themselves).
    virtual std::uint64_t skip_frames_due_by(std::int64_t now_ns) {
        (void)now_ns;
        return 0;
    }

    // One line for logs: device or folder, size, format.
    [[nodiscard]] virtual std::string description() const = 0;
};

}  // namespace mogao
