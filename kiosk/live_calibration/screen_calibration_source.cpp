// SPDX-License-Identifier: Apache-2.0
#include "kiosk/live_calibration/screen_calibration_source.h"

#include <fmt/format.h>

#include "appliance/calibration/mpcdi_reader.h"
#include "appliance/calibration/mpcdi_screen.h"
#include "appliance/warp/calibration_validation.h"
#include "appliance/warp/ideal_calibration.h"

namespace mogao {

ScreenCalibration load_screen_calibration(const CalibrationConfig& config, ImageSize content,
                                          std::vector<std::string>* notes) {
    ScreenCalibration screen;
    if (config.mpcdi.empty()) {
        IdealCalibrationParams params;
        params.projectors = config.projectors;
        params.overlap = config.overlap;
        params.output = config.output;
        params.content = content;
        params.gamma = config.gamma;
        screen = make_ideal_calibration(params);
    } else {
        screen = to_screen_calibration(read_mpcdi(config.mpcdi, notes), {}, notes);
        if (!(screen.content == content) && notes != nullptr) {
            notes->push_back(fmt::format("{}: calibrated for a {}x{} content frame, the farm renders {}x{} (resampled)",
                                         config.mpcdi.string(), screen.content.width, screen.content.height,
                                         content.width, content.height));
        }
    }
    validate_screen(screen);
    return screen;
}

}  // namespace mogao
