// SPDX-License-Identifier: Apache-2.0
// Fuzz target: a JPEG frame from the farm decoded by JpegDecoder (the appliance'\''s decode stage). Documented errors
// are caught; anything else (a crash, a sanitizer report, an exception of another type) is a finding.
#include <cstddef>
#include <cstdint>

#include "common/codec_errors.h"
#include "common/jpeg_codec.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static mogao::JpegDecoder decoder;
    try {
        static_cast<void>(decoder.decode({data, size}));
    } catch (const mogao::DecodeError&) {}
    return 0;
}
