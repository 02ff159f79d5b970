// SPDX-License-Identifier: Apache-2.0
// MjpegDecoder: decodes Motion-JPEG camera frames straight to grey with TurboJPEG (libjpeg-turbo
// 2.1 "tj" API). Owns one tjhandle (RAII, move-only) reused for every frame; not thread-safe.
//
// Decoding to TJPF_GRAY only runs the luma IDCT and skips colour conversion. UVC cameras often
// omit the Huffman tables (DHT) in their frames; libjpeg-turbo then uses the standard tables of
// ITU-T T.81 Annex K, which is what those cameras encode with.
//
// Errors (common/result.h): EBADMSG for empty, truncated or corrupt data (TurboJPEG's message),
// for a libjpeg warning (a frame with corrupt data decodes partly grey; the tracker must not see
// it), and for a size other than the one negotiated with the driver; ENOMEM if no handle.
#pragma once

#include <cstdint>
#include <span>

#include "common/result.h"
#include "common/unique_handle.h"
#include "drivers/camera/camera_frame.h"

namespace mogao {

class MjpegDecoder {
public:
    [[nodiscard]] static Result<MjpegDecoder> create();

    // Decodes `jpeg` into `out`. expected_width/height: the size negotiated with the driver; 0
    // accepts any size up to kMaxCaptureDimension (replay of loose JPEG files). EINVAL on a
    // moved-from decoder.
    [[nodiscard]] Status decode_grey(std::span<const std::uint8_t> jpeg, GrayImage& out, int expected_width = 0,
                                     int expected_height = 0);

private:
    // tjhandle is void* in TurboJPEG 2.x, which keeps turbojpeg.h out of this header; tjDestroy.
    struct Traits {
        using Value = void*;
        static constexpr void* null() noexcept { return nullptr; }
        static void close(void* handle) noexcept;
    };
    explicit MjpegDecoder(void* handle) noexcept : handle_(handle) {}
    UniqueHandle<Traits> handle_;  // move-only; null when moved from
};

}  // namespace mogao
