// SPDX-License-Identifier: Apache-2.0
// report.json's "colour" object, as both calibration jobs write it (the rig's, calibrate_job.h, and the on-site one,
// kiosk/calibrate/on_site_job.h): what the colour step measured (colour_calibration.h) and what the outputs will
// take off each frame of the screen's own light (indirect_light.h). Units as in ColourResult; keys in
// docs/calibration.md ("Colour and black level", "The screen and the lens shift").
#pragma once

#include <nlohmann/json.hpp>

#include "appliance/autocal/colour_calibration.h"
#include "appliance/autocal/indirect_light.h"

namespace mogao::autocal {

// The colour step's measurements: captures, matched white, black and white floors, the camera's vignetting, the
// screen's half-gain angle and reflectance for its own light, each projector's black, gain, fall-off and responses.
[[nodiscard]] nlohmann::json colour_report(const ColourResult& colour);

// Whether the outputs take the screen's own light off each frame (`indirect` null: they do not, or the screen
// measured too little of it) and, if so, the field for white content: the share of the calibrated white taken off
// (content units), largest and mean over the patches.
[[nodiscard]] nlohmann::json indirect_light_report(const IndirectLight* indirect);

}  // namespace mogao::autocal
