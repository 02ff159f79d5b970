// SPDX-License-Identifier: Apache-2.0
// LastGoodFrame: the content frame the outputs show, and the rule that keeps it.
//
// accept() decodes a frame's JPEG completely (TurboJPEG through JpegDecoder, which treats libjpeg's
// "warnings" — truncated data, bad Huffman codes — as errors) into a fresh image and only then
// makes it current. A frame that fails (corrupt or truncated JPEG, decoded size differing from the
// size the farm declared, a request id not newer than the current one) is rejected: the reason is
// returned, and the current frame is left exactly as it was. So the outputs never show a
// half-decoded frame and never go back to an older one; they keep the last good frame until a
// newer good one arrives.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "common/image.h"
#include "common/jpeg_codec.h"
#include "common/link_types.h"

namespace mogao {

// A decoded frame and what the kiosk reports about it.
struct ContentFrame {
    Rgb8Image image;                  // sRGB RGB8, rows top first
    std::uint64_t request_id = 0;     // the view request it answers (increasing)
    std::uint64_t link_frame_id = 0;  // per link session
    ViewerPose pose;                  // the pose it was rendered for
    FrameTimestamps times;            // request (appliance clock) ... receive (appliance clock)
    std::size_t jpeg_bytes = 0;
    double decode_ms = 0;       // TurboJPEG decode time on the kiosk
    std::uint32_t spp = 0;      // samples per pixel as the farm served it (0: not reported)
    std::uint32_t bounces = 0;  // indirect bounces as the farm served it
};

class LastGoodFrame {
public:
    LastGoodFrame() = default;  // JpegDecoder: throws DecodeError if TurboJPEG cannot allocate

    // Decodes `frame`. Returns an empty string when the frame became current, otherwise the reason
    // it was rejected ("request 12: JPEG decode failed: ...") and the current frame is unchanged.
    [[nodiscard]] std::string accept(const LinkFrame& frame);

    // The frame on screen; nullptr before the first good frame.
    [[nodiscard]] const ContentFrame* current() const { return current_ ? &*current_ : nullptr; }

    [[nodiscard]] std::uint64_t accepted() const { return accepted_; }
    [[nodiscard]] std::uint64_t rejected() const { return rejected_; }

private:
    JpegDecoder decoder_;
    std::optional<ContentFrame> current_;
    std::uint64_t accepted_ = 0;
    std::uint64_t rejected_ = 0;
};

}  // namespace mogao
