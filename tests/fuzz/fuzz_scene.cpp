// SPDX-License-Identifier: Apache-2.0
// Fuzz target: scene JSON parsed by parse_scene (procedural meshes only: mesh files it names
// resolve against a folder that does not exist). Documented errors are caught; anything
// else (a crash, a sanitizer report, an exception of another type) is a finding.
#include <cstddef>
#include <cstdint>

#include "renderfarm/scene/mesh_io.h"
#include "renderfarm/scene/scene_file.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    mogao::SceneLoadOptions options;
    options.scans_dir = "/nonexistent/mogao-fuzz-scans";
    try {
        static_cast<void>(mogao::parse_scene(std::string(mogao::fuzz::text(data, size)),
                                             "/nonexistent/mogao-fuzz/scene.json", options));
    } catch (const mogao::SceneError&) {
    } catch (const mogao::MeshLoadError&) {}
    return 0;
}
