// SPDX-License-Identifier: Apache-2.0
// Fuzz target: PLY bytes (ASCII and binary, faces and triangle strips) parsed by parse_ply. Documented errors are
// caught; anything else (a crash, a sanitizer report, an exception of another type) is a finding.
#include <cstddef>
#include <cstdint>

#include "renderfarm/scene/mesh_io.h"
#include "renderfarm/scene/ply_reader.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        static_cast<void>(mogao::parse_ply(mogao::fuzz::text(data, size), "fuzz.ply"));
    } catch (const mogao::MeshLoadError&) {}
    return 0;
}
