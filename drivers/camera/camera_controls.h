// SPDX-License-Identifier: Apache-2.0
// Camera controls set when a live camera opens: exposure, gain and white balance, each left as the
// device has it, automatic, locked (the automatic loop stops and holds the value it has reached)
// or manual (a value, checked against the device's range).
//
// Why: a camera's auto-exposure in a dim hall picks long exposures that blur a moving hand, so
// tracking wants a short manual exposure and automatic gain; camera-based projector calibration
// wants exposure, gain and white balance all fixed (manual or locked) so that every captured pattern
// is measured with the same response.
//
// Units: exposure in microseconds (V4L2_CID_EXPOSURE_ABSOLUTE counts 100 us; libcamera
// controls::ExposureTime is in us); gain in the device's units (V4L2_CID_GAIN: driver-defined
// integer steps; libcamera controls::AnalogueGain: 1.0 = unity); white balance in kelvin
// (V4L2_CID_WHITE_BALANCE_TEMPERATURE; libcamera 0.0.3 has no settable colour temperature: manual
// white balance is refused there, lock works through AwbEnable).
//
// Errors: a manual value outside the device's range is EINVAL naming `name` (the kiosk passes its
// config key, e.g. "[navigation].camera_exposure_us"), the value and the range in the same unit; a
// control the device lacks is ENOTSUP naming `name` when `required`, and is skipped otherwise; a
// value outside the range of a setting that is not required (a default) is clamped into it. The
// capture's description() names what was skipped or clamped.
#pragma once

#include <string>

#include "common/result.h"

namespace mogao {

struct ControlSetting {
    enum class Mode {
        keep,       // leave the device's current setting alone
        automatic,  // the device's automatic loop (auto exposure, auto gain, auto white balance)
        lock,       // stop the automatic loop, holding the value it reached (settle first if needed)
        manual,     // stop the automatic loop and set `value`
    };
    Mode mode = Mode::keep;
    double value = 0.0;     // manual only, in the control's unit (above)
    bool required = false;  // a device without the control: ENOTSUP (true) or skipped (false)
    std::string name;       // how messages name this setting
};

struct CameraControls {
    ControlSetting exposure{ControlSetting::Mode::keep, 0.0, false, "exposure_us"};
    ControlSetting gain{ControlSetting::Mode::keep, 0.0, false, "gain"};
    ControlSetting white_balance{ControlSetting::Mode::keep, 0.0, false, "white_balance_k"};
};

// "keep", "auto", "lock", or the manual value with its unit: "manual 8000" (for logs).
[[nodiscard]] std::string describe(const ControlSetting& setting);

// The range of one integer device control (V4L2 VIDIOC_QUERY_EXT_CTRL), in device units.
struct ControlRange {
    long long minimum = 0;
    long long maximum = 0;
    long long step = 1;
};

// The device value for `value` (in the setting's unit) given device units of `unit` setting units
// (exposure: 100 us per V4L2 unit): rounded to the nearest step from the minimum. EINVAL naming
// `name`, the value and the range in setting units (with `unit_name`) when outside. Pure.
[[nodiscard]] Result<long long> to_device_value(const std::string& name, double value, const ControlRange& range,
                                                double unit, const std::string& unit_name);

}  // namespace mogao
