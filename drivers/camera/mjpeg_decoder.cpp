// SPDX-License-Identifier: Apache-2.0
#include "drivers/camera/mjpeg_decoder.h"

#include <turbojpeg.h>

#include <string>

#include "drivers/camera/pixel_format.h"

namespace mogao {

Result<MjpegDecoder> MjpegDecoder::create() {
    tjhandle handle = tjInitDecompress();
    if (handle == nullptr) return make_error(ENOMEM, std::string("tjInitDecompress: ") + tjGetErrorStr2(nullptr));
    return MjpegDecoder(handle);
}

void MjpegDecoder::Traits::close(void* handle) noexcept { tjDestroy(handle); }

Status MjpegDecoder::decode_grey(std::span<const std::uint8_t> jpeg, GrayImage& out, int expected_width,
                                 int expected_height) {
    if (!handle_) return make_error(EINVAL, "MjpegDecoder::decode_grey on a moved-from decoder");
    if (jpeg.empty()) return make_error(EBADMSG, "MJPEG frame: 0 bytes");
    tjhandle handle = handle_.get();
    int width = 0;
    int height = 0;
    int subsampling = 0;
    int colorspace = 0;
    // TurboJPEG 2.1 takes a non-const pointer but does not write through it.
    auto* data = const_cast<unsigned char*>(jpeg.data());
    const auto size = static_cast<unsigned long>(jpeg.size());
    if (tjDecompressHeader3(handle, data, size, &width, &height, &subsampling, &colorspace) != 0) {
        return make_error(EBADMSG, std::string("MJPEG frame header: ") + tjGetErrorStr2(handle));
    }
    if (width < 1 || height < 1 || width > kMaxCaptureDimension || height > kMaxCaptureDimension) {
        return make_error(EBADMSG, "MJPEG frame: size " + std::to_string(width) + "x" + std::to_string(height) +
                                       " outside [1, " + std::to_string(kMaxCaptureDimension) + "] per side");
    }
    if ((expected_width != 0 && width != expected_width) || (expected_height != 0 && height != expected_height)) {
        return make_error(EBADMSG, "MJPEG frame: size " + std::to_string(width) + "x" + std::to_string(height) +
                                       " differs from the negotiated " + std::to_string(expected_width) + "x" +
                                       std::to_string(expected_height));
    }
    out.width = width;
    out.height = height;
    out.pixels.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
    // Warnings are failures: TurboJPEG returns -1 for them too and the frame is partly garbage.
    if (tjDecompress2(handle, data, size, out.pixels.data(), width, width, height, TJPF_GRAY, 0) != 0) {
        return make_error(EBADMSG, std::string("MJPEG frame: ") + tjGetErrorStr2(handle));
    }
    return {};
}

}  // namespace mogao
