// SPDX-License-Identifier: Apache-2.0
// Fuzz target: a Motion-JPEG camera frame decoded by MjpegDecoder, grey and colour; the
// decoder is reused across inputs as on a real camera, so a frame that poisons it shows. Documented errors are caught;
// anything else (a crash, a sanitizer report, an exception of another type) is a finding.
#include <cstddef>
#include <cstdint>

#include "drivers/camera/mjpeg_decoder.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static auto decoder = mogao::MjpegDecoder::create();
    if (!decoder) return 0;
    mogao::GrayImage grey;
    mogao::Rgb8Image colour;
    static_cast<void>(decoder->decode_grey({data, size}, grey));
    static_cast<void>(decoder->decode_colour({data, size}, grey, colour));
    return 0;
}
