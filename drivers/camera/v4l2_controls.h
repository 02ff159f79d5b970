// SPDX-License-Identifier: Apache-2.0
// CameraControls (camera_controls.h) on a V4L2 device: which V4L2 controls stand for each setting
// (V4L2 uAPI, "Camera Control Reference" and "User Controls"), and reading them back.
//
//   exposure       V4L2_CID_EXPOSURE_AUTO (menu: AUTO, or APERTURE_PRIORITY where AUTO is not
//                  offered, as on most UVC cameras; MANUAL to lock or set) and
//                  V4L2_CID_EXPOSURE_ABSOLUTE (100 us units); V4L2_CID_EXPOSURE_AUTO_PRIORITY is
//                  cleared with a manual or locked exposure so the frame rate stays constant
//   gain           V4L2_CID_AUTOGAIN (boolean) and V4L2_CID_GAIN (device units)
//   white balance  V4L2_CID_AUTO_WHITE_BALANCE (boolean) and V4L2_CID_WHITE_BALANCE_TEMPERATURE (K)
// Lock: the automatic control is switched off and the value it reached is read back and written as
// the manual value (drivers that reset the value when leaving auto then keep it too).
// Order: automatic switches first, then values (a value control is inactive while its auto is on).
//
// Errors (common/result.h): see camera_controls.h; plus the errno of a refused VIDIOC_S_CTRL naming
// the device, the setting's name and the control.
#pragma once

#include <optional>
#include <string>

#include "common/result.h"
#include "drivers/camera/camera_controls.h"

namespace mogao {

// Applies `controls` to the open device `fd` (`device` names it in messages). Settings a device
// lacks and that are not required are appended to *skipped (comma separated) when non-null.
[[nodiscard]] Status apply_v4l2_controls(int fd, const std::string& device, const CameraControls& controls,
                                         std::string* skipped);

// The current values, in the units of camera_controls.h; nullopt where the device lacks the control.
struct CameraControlValues {
    std::optional<bool> auto_exposure;
    std::optional<double> exposure_us;
    std::optional<bool> auto_gain;
    std::optional<double> gain;
    std::optional<bool> auto_white_balance;
    std::optional<double> white_balance_k;
};
[[nodiscard]] CameraControlValues read_v4l2_controls(int fd);

}  // namespace mogao
