// SPDX-License-Identifier: Apache-2.0
// Internal to mogao_autocal: the colour step's pieces that calibrate_colour (colour_calibration.cpp, the
// measurement) takes from the correction (colour_correction.cpp). The method and its sources are in
// colour_calibration.h; units are those of the functions there (blacks in one channel's light, a
// projector's relative light F in [0, 1]).
#pragma once

#include <array>
#include <vector>

#include "appliance/autocal/colour_calibration.h"
#include "appliance/warp/response_curve.h"

namespace mogao::autocal::colour_detail {

// Step 3's black floor: the brightest black over a 801 x 101 grid of screen points (blacks' units).
[[nodiscard]] std::array<double, 3> black_floor(const std::vector<DeviceModel>& models, const ScreenModel& screen,
                                                const std::vector<std::array<double, 3>>& blacks);

// Step 4's LUT for one projector: the inverse of its measured response at each matched-white level.
[[nodiscard]] ResponseCurve measured_lut(const ProjectorPhotometry& pp, const ColourOptions& o);

// Step 4's white floor S: the least relative light F any projector gives where it shows content (blend > 0), as the
// screen's viewer sees it (its lens's fall-off times the screen's gain toward the viewer); 1 when every projector
// is flat and the screen matte.
[[nodiscard]] double white_floor(const std::vector<DeviceModel>& models, const ScreenModel& screen,
                                 const ScreenCalibration& calibration);

}  // namespace mogao::autocal::colour_detail
