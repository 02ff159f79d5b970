// SPDX-License-Identifier: Apache-2.0
// What a camera-based calibration job is asked to do, whatever drives it: the virtual rig's job
// (calibrate_job.h, `mogao-calibrate-sim rig`) and the on-site job (kiosk/calibrate/on_site_job.h,
// `mogao-calibrate`, from a camera or from captured images) both hold these settings, filled by the one
// flag set of calibration_flags.h.
#pragma once

#include "appliance/autocal/autocal.h"
#include "appliance/autocal/colour_calibration.h"
#include "appliance/autocal/self_check.h"
#include "common/pixel_rect.h"

namespace mogao::autocal {

struct CalibrationSettings {
    double scale = 1.0;             // projector and camera resolutions scaled (tests, demos), (0, 1]
    ImageSize content{1920, 1080};  // the content frame, pixels (the farm's frame)
    int alpha_bits = 16;            // alpha maps' bits, 8 or 16
    AutocalOptions options;         // the geometric calibration (autocal.h)
    bool colour = true;             // the photometric step (colour_calibration.h) after the geometry
    ColourOptions colour_options;
    // Whether the outputs take the screen's own light out of each frame (indirect_light.h; the kiosk's
    // [calibration] indirect_light): the ground-truth figures show content as such outputs show it.
    bool indirect_light = true;
    // The self-check after the geometry (self_check.h): marks through the new warp and blend, filmed; its
    // gate (self_check.max_mean_px, --max-self-check-px) refuses the calibration like the others.
    SelfCheckOptions self_check;
};

}  // namespace mogao::autocal
