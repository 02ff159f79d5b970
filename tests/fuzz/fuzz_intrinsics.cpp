// SPDX-License-Identifier: Apache-2.0
// Fuzz target: a camera intrinsics JSON file read by read_intrinsics (the tracker'\''s camera.json). Documented errors
// are caught; anything else (a crash, a sanitizer report, an exception of another type) is a finding.
#include <cstddef>
#include <cstdint>

#include <stdexcept>

#include "appliance/tracker/camera_intrinsics.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const mogao::fuzz::MemFile file(data, size);
    if (!file.valid()) return 0;
    try {
        static_cast<void>(mogao::read_intrinsics(file.path()));
    } catch (const mogao::CalibrationFileError&) {
    } catch (const std::invalid_argument&) {  // a value outside its documented range
    }
    return 0;
}
