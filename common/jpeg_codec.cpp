// SPDX-License-Identifier: Apache-2.0
#include "common/jpeg_codec.h"

#include <turbojpeg.h>

#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace mogao {
namespace {

// tjhandle is `void*` in TurboJPEG 2.x, so the headers can store it without including turbojpeg.h.
static_assert(std::is_same_v<tjhandle, void*>);

// JPEG stores width and height in 16 bits.
constexpr int kMaxJpegDimension = 65535;

std::string tj_reason(tjhandle handle) {
    // tjGetErrorStr2 is per handle, so concurrent encoders on other threads cannot overwrite it.
    const char* msg = tjGetErrorStr2(handle);
    return msg != nullptr ? msg : "unknown TurboJPEG error";
}

int tj_subsampling(Subsampling s) {
    switch (s) {
        case Subsampling::yuv444:
            return TJSAMP_444;
        case Subsampling::yuv422:
            return TJSAMP_422;
        case Subsampling::yuv420:
            return TJSAMP_420;
    }
    throw std::invalid_argument("JpegEncoder::encode: unknown subsampling");
}

// libjpeg-turbo 2.1.5: when tjDecompressHeader3 fails mid-header it longjmps out without
// jpeg_abort_decompress, so the handle keeps its half-parsed marker state and every later
// decode on it fails (even of a valid file, e.g. "Bogus DQT index"). A failed call therefore
// replaces the handle; that costs microseconds and only on the error path. Same for the encoder,
// to be safe against similar state after a failed tjCompress2.
void replace_handle(UniqueHandle<TjHandleTraits>& handle, tjhandle (*init)()) {
    handle.reset();
    handle.reset(init());  // nullptr only if malloc fails; the next call then reports that
}

}  // namespace

void TjHandleTraits::close(void* handle) noexcept { tjDestroy(handle); }

JpegEncoder::JpegEncoder() : handle_(tjInitCompress()) {
    if (!handle_) {
        throw EncodeError("JpegEncoder: tjInitCompress failed: " + tj_reason(nullptr));
    }
}

std::vector<std::uint8_t> JpegEncoder::encode(const Rgb8Image& image, int quality, Subsampling subsampling) {
    if (!handle_) throw std::logic_error("JpegEncoder::encode: no handle (moved from, or out of memory)");
    require_valid_image(image, "JpegEncoder::encode");
    if (quality < 1 || quality > 100) {
        throw std::invalid_argument("JpegEncoder::encode: quality " + std::to_string(quality) + " is outside 1..100");
    }
    const int w = image.size.width;
    const int h = image.size.height;
    if (w > kMaxJpegDimension || h > kMaxJpegDimension) {
        throw EncodeError("JpegEncoder::encode: " + std::to_string(w) + "x" + std::to_string(h) +
                          " exceeds the JPEG limit of 65535 per side");
    }
    const int samp = tj_subsampling(subsampling);

    // Compress straight into a vector sized by tjBufSize (the worst case for this size and
    // subsampling); TJFLAG_NOREALLOC guarantees TurboJPEG writes there and never tjAlloc()s its own.
    const unsigned long bound = tjBufSize(w, h, samp);
    if (bound == static_cast<unsigned long>(-1)) {
        throw EncodeError("JpegEncoder::encode: tjBufSize failed: " + tj_reason(nullptr));
    }
    std::vector<std::uint8_t> out(bound);
    unsigned char* dst = out.data();
    unsigned long size = bound;
    const int rc = tjCompress2(handle_.get(), image.pixels.data(), w, w * 3, h, TJPF_RGB, &dst, &size, samp, quality,
                               TJFLAG_NOREALLOC);
    if (rc != 0) {
        const std::string reason = tj_reason(handle_.get());
        replace_handle(handle_, tjInitCompress);
        throw EncodeError("JpegEncoder::encode: tjCompress2 failed for " + std::to_string(w) + "x" + std::to_string(h) +
                          " at quality " + std::to_string(quality) + ": " + reason);
    }
    out.resize(size);
    return out;
}

JpegDecoder::JpegDecoder() : handle_(tjInitDecompress()) {
    if (!handle_) {
        throw DecodeError("JpegDecoder: tjInitDecompress failed: " + tj_reason(nullptr));
    }
}

Rgb8Image JpegDecoder::decode(std::span<const std::uint8_t> jpeg) {
    if (!handle_) throw std::logic_error("JpegDecoder::decode: no handle (moved from, or out of memory)");
    if (jpeg.empty()) throw DecodeError("JpegDecoder::decode: no data (0 bytes)");
    if (jpeg.size() > std::numeric_limits<unsigned long>::max()) {
        throw DecodeError("JpegDecoder::decode: input too large");
    }
    const auto size = static_cast<unsigned long>(jpeg.size());

    int w = 0;
    int h = 0;
    int samp = 0;
    int colorspace = 0;
    if (tjDecompressHeader3(handle_.get(), jpeg.data(), size, &w, &h, &samp, &colorspace) != 0) {
        const std::string reason = tj_reason(handle_.get());
        replace_handle(handle_, tjInitDecompress);
        throw DecodeError("JpegDecoder::decode: bad JPEG header (" + std::to_string(jpeg.size()) +
                          " bytes): " + reason);
    }
    // Refuse before allocating: the header's size is attacker/corruption controlled.
    if (w <= 0 || h <= 0 || w > kMaxDecodedDimension || h > kMaxDecodedDimension) {
        throw DecodeError("JpegDecoder::decode: declared size " + std::to_string(w) + "x" + std::to_string(h) +
                          " is outside 1.." + std::to_string(kMaxDecodedDimension) + " per side");
    }
    if (colorspace == TJCS_CMYK || colorspace == TJCS_YCCK) {
        throw DecodeError("JpegDecoder::decode: CMYK/YCCK JPEG is not supported (frames are sRGB)");
    }

    Rgb8Image image(ImageSize{w, h});
    // STOPONWARNING: libjpeg treats truncation and entropy-coding damage as warnings and fills the
    // rest with grey; we want an error instead. LIMITSCANS: a progressive file with thousands of
    // scans is a known CPU-exhaustion input. Even with these flags, 2.1 returns -1 with a warning
    // code for any warning it still saw, so any non-zero return is a failure.
    const int flags = TJFLAG_STOPONWARNING | TJFLAG_LIMITSCANS;
    if (tjDecompress2(handle_.get(), jpeg.data(), size, image.pixels.data(), w, w * 3, h, TJPF_RGB, flags) != 0) {
        const bool warning = tjGetErrorCode(handle_.get()) == TJERR_WARNING;
        const std::string reason = tj_reason(handle_.get());
        replace_handle(handle_, tjInitDecompress);
        throw DecodeError(std::string("JpegDecoder::decode: ") + (warning ? "damaged" : "corrupt") + " " +
                          std::to_string(w) + "x" + std::to_string(h) + " JPEG (" + std::to_string(jpeg.size()) +
                          " bytes): " + reason);
    }
    return image;
}

}  // namespace mogao
