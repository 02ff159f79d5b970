// SPDX-License-Identifier: Apache-2.0
// Which projector calibration each output shows.
//
// Rules, in order: output i shows projector i when their sizes are equal (the normal case: outputs
// in connector order = projectors left to right, as mogao-calibrate writes them); an output left
// over takes the first unused projector of its size; then the first unused projector of any size
// (its warp is in normalised coordinates, so it still lands on the right part of the screen, at
// the output's resolution; a note says so). Outputs beyond the projectors show nothing (black),
// projectors beyond the outputs are not shown; both get a note.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "common/projector_calibration.h"
#include "drivers/output.h"

namespace mogao {

// result[i] = index into screen.projectors for output i, or nullopt (unlit). Notes are appended.
[[nodiscard]] std::vector<std::optional<std::size_t>> assign_projectors(const std::vector<OutputInfo>& outputs,
                                                                        const ScreenCalibration& screen,
                                                                        std::vector<std::string>* notes);

}  // namespace mogao
