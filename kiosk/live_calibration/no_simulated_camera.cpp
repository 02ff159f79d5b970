// SPDX-License-Identifier: Apache-2.0
// The appliance's mogao-kiosk carries no virtual rig: a "rig:" screen camera is refused at start
// (selfcal_setup.h). mogao-kiosk-sim links kiosk/simulation/rig_screen_camera.cpp instead.
#include "kiosk/live_calibration/selfcal_setup.h"

namespace mogao {

SimulatedScreenCamera built_in_simulated_camera() { return {}; }

}  // namespace mogao
