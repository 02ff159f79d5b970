// SPDX-License-Identifier: Apache-2.0
// JPEG encode/decode with TurboJPEG (libjpeg-turbo 2.1 "tj" API, as shipped by Debian 12).
//
// Each class owns one tjhandle and reuses it for every frame: creating a handle allocates the
// libjpeg state, which is wasted work at 60 frames per second. A handle is not thread-safe, so use
// one encoder/decoder per thread; the classes are movable but not copyable for that reason.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "common/codec_errors.h"
#include "common/image.h"
#include "common/unique_handle.h"

namespace mogao {

// Chroma subsampling. 4:2:0 halves chroma both ways (smallest files; the default, as for video);
// 4:4:4 keeps full chroma for thin coloured edges such as text overlays.
enum class Subsampling { yuv444, yuv422, yuv420 };

inline constexpr int kDefaultJpegQuality = 85;  // matches Quality::jpeg_quality in view_request.h

// One tjhandle (void* in TurboJPEG 2.x, which keeps turbojpeg.h out of this header); tjDestroy.
struct TjHandleTraits {
    using Value = void*;
    static constexpr void* null() noexcept { return nullptr; }
    static void close(void* handle) noexcept;
};

class JpegEncoder {
public:
    JpegEncoder();  // throws EncodeError if TurboJPEG cannot allocate a handle

    // Baseline JFIF of an sRGB8 image. quality is 1..100 (std::invalid_argument otherwise, and for
    // an inconsistent image); EncodeError names TurboJPEG's reason if compression fails.
    [[nodiscard]] std::vector<std::uint8_t> encode(const Rgb8Image& image, int quality = kDefaultJpegQuality,
                                                   Subsampling subsampling = Subsampling::yuv420);

private:
    UniqueHandle<TjHandleTraits> handle_;  // null when moved from (or after a failed re-init)
};

class JpegDecoder {
public:
    JpegDecoder();  // throws DecodeError if TurboJPEG cannot allocate a handle

    // Decodes a whole JPEG (any subsampling, grayscale or colour) to RGB8. Throws DecodeError for
    // empty, truncated or corrupt data, for CMYK, and for a declared size above
    // kMaxDecodedDimension on either side (checked from the header, before any allocation).
    // libjpeg "warnings" (premature end of data, bad Huffman code, ...) are errors here: such an
    // image is partly grey or smeared and the appliance must never project it.
    [[nodiscard]] Rgb8Image decode(std::span<const std::uint8_t> jpeg);

private:
    UniqueHandle<TjHandleTraits> handle_;
};

}  // namespace mogao
