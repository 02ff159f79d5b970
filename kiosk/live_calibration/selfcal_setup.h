// SPDX-License-Identifier: Apache-2.0
// The kiosk's [selfcal] start-up step (kiosk/main.cpp, after the outputs; docs/kiosk.md
// "Self-recalibration"): reads the fitted models beside the MPCDI (appliance/autocal/model_store.h),
// checks them against the calibration on the wall, opens the screen camera and starts the
// SelfcalWorker whose corrections go through the calibration swap and are written back to the MPCDI
// file (appliance/selfcal/calibration_store.h: atomic, the previous one kept as <file>.last-good).
//
// Screen cameras ([selfcal].camera):
//   "v4l2:/dev/videoN"  a real camera, opened with exposure and gain locked or manual
//                       (drivers/camera/camera_controls.h; [selfcal].camera_exposure_us, camera_gain)
//                       at the models' camera resolution (or camera_size, which must equal it). Its
//                       8-bit luma is taken as sRGB-encoded (IEC 61966-2-1) and decoded to linear
//                       [0, 1], as the monitor's frames are (an assumption of the camera's transfer
//                       curve: a camera with another one biases brightness, which the ORB features
//                       and the pose fits tolerate, not geometry).
//   "rig:<rig.toml>"    A SIMULATION: the virtual rig's camera (appliance/rig CameraSimulator)
//                       rendering what the wall's calibration shows through the rig file's TRUE
//                       (possibly bumped) projectors, at the models' resolutions (scaled_rig). For
//                       tests and demos; it measures nothing on a real wall.
// Errors: KioskSetupError(1, "selfcal: ...") naming the file and field (models file unreadable or
// not matching the MPCDI, camera that cannot open or delivers another size, rig file invalid).
#pragma once

#include <functional>
#include <memory>
#include <optional>

#include "common/projector_calibration.h"
#include "kiosk/config/kiosk_config.h"
#include "kiosk/live_calibration/calibration_inbox.h"
#include "kiosk/live_calibration/selfcal_worker.h"

namespace mogao {

// Opens a simulated screen camera ("rig:") for the models. Errors: KioskSetupError as above.
using SimulatedScreenCamera =
    std::function<SelfcalWorker::Camera(const SelfcalConfig& config, const selfcal::SystemModel& model)>;

// The simulated screen camera this program was built with, defined once per executable (not in
// the mogao_kiosk library): empty in the appliance's mogao-kiosk
// (kiosk/live_calibration/no_simulated_camera.cpp), the virtual rig's in mogao-kiosk-sim
// (kiosk/simulation/rig_screen_camera.cpp).
[[nodiscard]] SimulatedScreenCamera built_in_simulated_camera();

// nullptr when [selfcal].enabled is false. `wall`: the calibration the outputs show, read from
// `mpcdi` ([calibration] source), where corrections are written back. `inbox` must outlive the
// worker. `simulated` empty: a "rig:" camera is refused.
[[nodiscard]] std::unique_ptr<SelfcalWorker> start_selfcal(const SelfcalConfig& config,
                                                           const std::filesystem::path& mpcdi,
                                                           const ScreenCalibration& wall, CalibrationInbox& inbox,
                                                           const SimulatedScreenCamera& simulated = {});

// The warp grid step (1..64) that autocal::calibration_from_models uses to build grids of the sizes
// `calibration` has, so that a correction can be blended with it; nullopt when none does.
[[nodiscard]] std::optional<int> warp_step_of(const ScreenCalibration& calibration);

}  // namespace mogao
