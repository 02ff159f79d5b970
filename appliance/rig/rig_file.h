// SPDX-License-Identifier: Apache-2.0
// Rig files (rigs/*.toml, TOML v1.0 read with toml11): the virtual rig's screen, projectors, camera
// and prior. Fields and units: docs/calibration.md, "Rig files"; rigs/standard.toml is the
// annotated example.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>

#include "appliance/rig/rig_model.h"

namespace mogao::rig {

// A rig file that cannot be read or holds a bad value. The message starts with
// "rig file '<path>'" and names the field and its limit.
class RigError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Reads and validates (validate_rig) a rig file. Returns a complete rig or throws RigError. A projector's `procam`
// path is resolved against the file's folder (parse_rig keeps it as written).
[[nodiscard]] VirtualRig load_rig(const std::filesystem::path& path);

// Same from TOML text; `name` is used in messages.
[[nodiscard]] VirtualRig parse_rig(const std::string& toml_text, const std::string& name);

}  // namespace mogao::rig
