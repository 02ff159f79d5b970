// SPDX-License-Identifier: Apache-2.0
// What the calibration is told by a rig description (rig_model.h: a rigs/*.toml file, or the on-site calibration's
// site file in the same format): the prior, and the description at reduced resolution. Product code: it reads the
// description only, never the virtual rig's simulation (rig_bridge.h holds that side).
#pragma once

#include "appliance/autocal/autocal.h"
#include "appliance/rig/rig_model.h"

namespace mogao::autocal {

// The rig at reduced resolution: projector and camera sizes and intrinsics scaled, the projectors'
// defocus (blur_px) with them (errors in
// projector pixels then scale with `projector_scale`). Scales in (0, 1].
[[nodiscard]] rig::VirtualRig scaled_rig(const rig::VirtualRig& rig, double projector_scale, double camera_scale);

// What the calibration is told about a rig: screen, camera intrinsics (focal, principal point and
// distortion errors applied, as a chessboard calibration leaves them; never the truth's) and
// pose (position and angle errors applied), projector resolutions, data-sheet intrinsics (focal
// error applied) and ids; the rig's [prior] section holds the errors.
[[nodiscard]] CalibrationPrior prior_from_rig(const rig::VirtualRig& rig);

}  // namespace mogao::autocal
