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

#include "drivers/camera/camera_frame.h"
#include "common/result.h"

namespace mogao {

class MjpegDecoder {
public:
    [[nodiscard]] static Result<MjpegDecoder> create();

    MjpegDecoder(MjpegDecoder&& other) noexcept;
    MjpegDecoder& operator=(MjpegDecoder&& other) noexcept;
    MjpegDecoder(const MjpegDecoder&) = delete;
    MjpegDecoder& operator=(const MjpegDecoder&) = delete;
    ~MjpegDecoder();

    // Decodes `jpeg` into `out`. expected_width/height: the size negotiated with the driver; 0
    // accepts any size up to kMaxCaptureDimension (replay of loose JPEG files).
    [[nodiscard]] Status decode_grey(std::span<const std::uint8_t> jpeg, GrayImage& out, int expected_width = 0,
                                     int expected_height = 0);

private:
    explicit MjpegDecoder(void* handle) noexcept : handle_(handle) {}
    void* handle_ = nullptr;  // tjhandle; void* keeps turbojpeg.h out of this header
};

}  // namespace mogao
