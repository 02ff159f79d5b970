// SPDX-License-Identifier: Apache-2.0
// Fuzz target: a PNG alpha/beta map decoded by decode_png_map (MPCDI blending). Documented errors are caught; anything
// else (a crash, a sanitizer report, an exception of another type) is a finding.
#include <cstddef>
#include <cstdint>

#include "appliance/calibration/mpcdi_error.h"
#include "appliance/calibration/png_codec.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        static_cast<void>(mogao::decode_png_map({data, size}, "fuzz"));
    } catch (const mogao::MpcdiError&) {}
    return 0;
}
