// SPDX-License-Identifier: Apache-2.0
// Fuzz target: an MPCDI archive (zip, mpcdi.xml, PFM and PNG maps) read by read_mpcdi,
// the appliance's calibration input from elsewhere. Documented errors are caught; anything
// else (a crash, a sanitizer report, an exception of another type) is a finding.
#include <cstddef>
#include <cstdint>

#include "appliance/calibration/mpcdi_error.h"
#include "appliance/calibration/mpcdi_reader.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const mogao::fuzz::MemFile file(data, size);
    if (!file.valid()) return 0;
    try {
        static_cast<void>(mogao::read_mpcdi(file.path()));
    } catch (const mogao::MpcdiError&) {}
    return 0;
}
