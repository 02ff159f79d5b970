// SPDX-License-Identifier: Apache-2.0
#include "drivers/camera/mjpeg_decoder.h"

#include <turbojpeg.h>

#include <string>

#include "drivers/camera/pixel_format.h"

namespace mogao {
namespace {

// STOPONWARNING: truncation and entropy-coding damage are libjpeg warnings that otherwise decode a
// partly grey frame with success; LIMITSCANS: at most 500 scans (progressive CPU-exhaustion input).
constexpr int kDecodeFlags = TJFLAG_STOPONWARNING | TJFLAG_LIMITSCANS;

}  // namespace

Result<MjpegDecoder> MjpegDecoder::create() {
    tjhandle handle = tjInitDecompress();
    if (handle == nullptr) return make_error(ENOMEM, std::string("tjInitDecompress: ") + tjGetErrorStr2(nullptr));
    return MjpegDecoder(handle);
}

void MjpegDecoder::Traits::close(void* handle) noexcept { tjDestroy(handle); }

Status MjpegDecoder::fail(const std::string& message) {
    // libjpeg-turbo 2.1 can leave a handle unusable after a failed call (see the header): start afresh.
    handle_.reset();
    handle_.reset(tjInitDecompress());
    return make_error(EBADMSG, message);
}

Status MjpegDecoder::read_header(std::span<const std::uint8_t> jpeg, int expected_width, int expected_height,
                                 int& width, int& height) {
    if (!handle_) return make_error(EINVAL, "MjpegDecoder: no handle (moved from, or out of memory)");
    if (jpeg.empty()) return make_error(EBADMSG, "MJPEG frame: 0 bytes");
    if (jpeg.size() > kMaxMjpegFrameBytes) {
        return make_error(EBADMSG, "MJPEG frame: " + std::to_string(jpeg.size()) + " bytes, above the limit of " +
                                       std::to_string(kMaxMjpegFrameBytes));
    }
    int subsampling = 0;
    int colorspace = 0;
    if (tjDecompressHeader3(handle_.get(), jpeg.data(), static_cast<unsigned long>(jpeg.size()), &width, &height,
                            &subsampling, &colorspace) != 0) {
        return fail(std::string("MJPEG frame header: ") + tjGetErrorStr2(handle_.get()));
    }
    if (width < 1 || height < 1 || width > kMaxCaptureDimension || height > kMaxCaptureDimension) {
        return fail("MJPEG frame: size " + std::to_string(width) + "x" + std::to_string(height) + " outside [1, " +
                    std::to_string(kMaxCaptureDimension) + "] per side");
    }
    if ((expected_width != 0 && width != expected_width) || (expected_height != 0 && height != expected_height)) {
        return fail("MJPEG frame: size " + std::to_string(width) + "x" + std::to_string(height) +
                    " differs from the negotiated " + std::to_string(expected_width) + "x" +
                    std::to_string(expected_height));
    }
    if (colorspace == TJCS_CMYK || colorspace == TJCS_YCCK) {
        return fail("MJPEG frame: CMYK/YCCK JPEG is not a camera format");
    }
    return {};
}

Status MjpegDecoder::decode_grey(std::span<const std::uint8_t> jpeg, GrayImage& out, int expected_width,
                                 int expected_height) {
    int width = 0;
    int height = 0;
    if (Status s = read_header(jpeg, expected_width, expected_height, width, height); !s) return s;
    out.width = width;
    out.height = height;
    out.pixels.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
    // Warnings are failures: TurboJPEG returns -1 for them too and the frame is partly garbage.
    if (tjDecompress2(handle_.get(), jpeg.data(), static_cast<unsigned long>(jpeg.size()), out.pixels.data(), width,
                      width, height, TJPF_GRAY, kDecodeFlags) != 0) {
        return fail(std::string("MJPEG frame: ") + tjGetErrorStr2(handle_.get()));
    }
    return {};
}

Status MjpegDecoder::decode_colour(std::span<const std::uint8_t> jpeg, GrayImage& grey, Rgb8Image& colour,
                                   int expected_width, int expected_height) {
    int width = 0;
    int height = 0;
    if (Status s = read_header(jpeg, expected_width, expected_height, width, height); !s) return s;
    colour.size = ImageSize{width, height};
    colour.pixels.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3);
    if (tjDecompress2(handle_.get(), jpeg.data(), static_cast<unsigned long>(jpeg.size()), colour.pixels.data(), width,
                      width * 3, height, TJPF_RGB, kDecodeFlags) != 0) {
        return fail(std::string("MJPEG frame: ") + tjGetErrorStr2(handle_.get()));
    }
    grey_from_rgb(colour, grey);
    return {};
}

}  // namespace mogao
