// SPDX-License-Identifier: Apache-2.0
// The projector calibration the kiosk starts with: the MPCDI file of the configuration (2d
// profile, appliance/calibration) or the ideal N-projector layout (appliance/warp), checked with
// validate_screen before any output uses it.
//
// Errors: MpcdiError (read_mpcdi/to_screen_calibration; names the file, entry and field) or
// std::invalid_argument (ideal parameters, validation; names the field and limit).
#pragma once

#include <string>
#include <vector>

#include "common/projector_calibration.h"
#include "kiosk/config/kiosk_config.h"

namespace mogao {

// `content` is the farm's frame size ([quality].content): the ideal layout is made for it; an
// MPCDI buffer of another size still works (the warps are normalised) and adds a note.
[[nodiscard]] ScreenCalibration load_screen_calibration(const CalibrationConfig& config, ImageSize content,
                                                        std::vector<std::string>* notes);

}  // namespace mogao
