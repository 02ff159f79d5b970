// SPDX-License-Identifier: Apache-2.0
#include "drivers/camera/camera_controls.h"

#include <cmath>
#include <sstream>

namespace mogao {
namespace {

std::string number(double v) {
    std::ostringstream out;
    out << v;
    return out.str();
}

}  // namespace

std::string describe(const ControlSetting& setting) {
    switch (setting.mode) {
        case ControlSetting::Mode::keep:
            return "keep";
        case ControlSetting::Mode::automatic:
            return "auto";
        case ControlSetting::Mode::lock:
            return "lock";
        case ControlSetting::Mode::manual:
            return "manual " + number(setting.value);
    }
    return "?";
}

Result<long long> to_device_value(const std::string& name, double value, const ControlRange& range, double unit,
                                  const std::string& unit_name) {
    const auto in_units = [unit](long long device) { return number(static_cast<double>(device) * unit); };
    const std::string limits = "[" + in_units(range.minimum) + ", " + in_units(range.maximum) + "]" +
                               (unit_name.empty() ? "" : " " + unit_name);
    if (!std::isfinite(value) || !std::isfinite(unit) || unit <= 0) {
        return make_error(EINVAL,
                          name + " = " + number(value) + " is not a number within the device's range " + limits);
    }
    const double device = value / unit;
    // Half a step of tolerance: 8000 us on a 100 us-unit control with minimum 3 is reachable as 80.
    const long long step = range.step > 0 ? range.step : 1;
    if (device < static_cast<double>(range.minimum) - 0.5 || device > static_cast<double>(range.maximum) + 0.5) {
        return make_error(EINVAL, name + " = " + number(value) + " is outside the device's range " + limits);
    }
    const double steps = std::round((device - static_cast<double>(range.minimum)) / static_cast<double>(step));
    long long v = range.minimum + static_cast<long long>(steps) * step;
    if (v > range.maximum) v -= step;
    if (v < range.minimum) v = range.minimum;
    return v;
}

}  // namespace mogao
