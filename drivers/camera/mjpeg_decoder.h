// SPDX-License-Identifier: Apache-2.0
// MjpegDecoder: decodes Motion-JPEG camera frames with TurboJPEG (libjpeg-turbo 2.1 "tj" API),
// straight to grey, or to colour (R'G'B') and grey. Owns one tjhandle (RAII, move-only) reused for
// every frame; not thread-safe.
//
// Decoding to TJPF_GRAY only runs the luma IDCT and skips colour conversion. UVC cameras often
// omit the Huffman tables (DHT) in their frames; libjpeg-turbo then uses the standard tables of
// ITU-T T.81 Annex K, which is what those cameras encode with. Colour frames are JFIF (full-range
// BT.601 Y'CbCr, ITU-T T.871), converted by libjpeg-turbo; their grey is the BT.601 luma of the
// decoded R'G'B' (pixel_format.h, grey_from_rgb), within 1 of the decoded Y'.
//
// Recovery: a corrupt frame never poisons the decoder. libjpeg-turbo 2.1 leaves the handle unusable
// after some header errors (a bogus marker length, SOS before SOF: every later frame then fails),
// so after any failure the handle is replaced by a fresh one, as common/jpeg_codec.cpp does.
//
// Limits (as common/jpeg_codec.cpp): at most kMaxMjpegFrameBytes per frame, a declared size
// within [1, kMaxCaptureDimension] per side checked from the header before any allocation,
// TJFLAG_LIMITSCANS (a progressive frame with hundreds of scans is a CPU-exhaustion input) and
// TJFLAG_STOPONWARNING.
//
// Errors (common/result.h): EBADMSG for empty, oversized, truncated or corrupt data (TurboJPEG's
// message), for a libjpeg warning (a frame with corrupt data decodes partly grey; the tracker must
// not see it), and for a size other than the one negotiated with the driver; ENOMEM if no handle;
// EINVAL on a decoder without a handle (moved from, or its replacement could not be allocated).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "common/image.h"
#include "common/result.h"
#include "common/unique_handle.h"
#include "drivers/camera/camera_frame.h"

namespace mogao {

// Largest MJPEG frame accepted, in bytes: above any real frame of kMaxCaptureDimension per side
// at camera qualities, small enough that a runaway bytesused cannot stall the tracker.
inline constexpr std::size_t kMaxMjpegFrameBytes = std::size_t{64} << 20;

class MjpegDecoder {
public:
    [[nodiscard]] static Result<MjpegDecoder> create();

    // Decodes `jpeg` into `out`. expected_width/height: the size negotiated with the driver; 0
    // accepts any size up to kMaxCaptureDimension (replay of loose JPEG files).
    [[nodiscard]] Status decode_grey(std::span<const std::uint8_t> jpeg, GrayImage& out, int expected_width = 0,
                                     int expected_height = 0);

    // Decodes `jpeg` to colour (`colour`, R'G'B' as the JPEG encodes it) and its luma (`grey`).
    // Same sizes, limits and errors as decode_grey.
    [[nodiscard]] Status decode_colour(std::span<const std::uint8_t> jpeg, GrayImage& grey, Rgb8Image& colour,
                                       int expected_width = 0, int expected_height = 0);

private:
    // tjhandle is void* in TurboJPEG 2.x, which keeps turbojpeg.h out of this header; tjDestroy.
    struct Traits {
        using Value = void*;
        static constexpr void* null() noexcept { return nullptr; }
        static void close(void* handle) noexcept;
    };
    explicit MjpegDecoder(void* handle) noexcept : handle_(handle) {}
    // Header checks; sets width/height. On failure the handle has been replaced.
    Status read_header(std::span<const std::uint8_t> jpeg, int expected_width, int expected_height, int& width,
                       int& height);
    Status fail(const std::string& message);  // replaces the handle, returns EBADMSG
    UniqueHandle<Traits> handle_;             // null when moved from (or if a replacement failed)
};

}  // namespace mogao
