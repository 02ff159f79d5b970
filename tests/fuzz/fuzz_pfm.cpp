// SPDX-License-Identifier: Apache-2.0
// Fuzz target: a PFM warp map decoded by decode_pfm (MPCDI geometry). Documented errors are caught; anything
// else (a crash, a sanitizer report, an exception of another type) is a finding.
#include <cstddef>
#include <cstdint>

#include "appliance/calibration/mpcdi_error.h"
#include "appliance/calibration/pfm_codec.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        static_cast<void>(mogao::decode_pfm({data, size}, "fuzz"));
    } catch (const mogao::MpcdiError&) {}
    return 0;
}
