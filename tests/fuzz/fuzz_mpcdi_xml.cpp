// SPDX-License-Identifier: Apache-2.0
// Fuzz target: mpcdi.xml text parsed by parse_mpcdi_xml (geometry, frustums, buffers). Documented errors are caught;
// anything else (a crash, a sanitizer report, an exception of another type) is a finding.
#include <cstddef>
#include <cstdint>

#include "appliance/calibration/mpcdi_error.h"
#include "appliance/calibration/mpcdi_xml.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        static_cast<void>(mogao::parse_mpcdi_xml(mogao::fuzz::text(data, size), "fuzz", nullptr));
    } catch (const mogao::MpcdiError&) {}
    return 0;
}
