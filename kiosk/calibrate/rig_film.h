// SPDX-License-Identifier: Apache-2.0
// SIMULATION, test and documentation side (not installed, not linked into mogao-calibrate): the
// technician's camera on a virtual rig, for the captured-images route (images_job.h). Each pattern
// `mogao-calibrate patterns` wrote is read back from its PNG files (what each projector would be fed),
// shown through the rig's TRUE projectors, and what the rig's camera sees (appliance/rig
// CameraSimulator: responses, black levels, fall-off, ambient light, noise, blur, 8-bit
// quantisation) is written as an 8-bit PNG of the rig's linear camera codes to the file captures.json
// names (calibrate with --camera-transfer linear). Camera noise frame = first_frame + the pattern's order.
//
//   mogao-rig-film film --rig FILE [--scale S] --patterns DIR
//   mogao-rig-film measure --rig FILE [--scale S] --mpcdi FILE      geometry against the rig's truth
#pragma once

#include <cstdint>
#include <filesystem>

#include "appliance/rig/virtual_rig.h"

namespace mogao::calibrate {

// Films every pattern of DIR/patterns.json into the files of DIR/captures.json; returns their count.
// Throws std::runtime_error naming the file (a manifest of other projector sizes than the rig's, an
// unreadable PNG).
int film_patterns(const std::filesystem::path& dir, const rig::VirtualRig& rig, std::uint64_t first_frame = 0);

}  // namespace mogao::calibrate
