// SPDX-License-Identifier: Apache-2.0
#include "drivers/camera/v4l2_controls.h"
#include "drivers/camera/v4l2_ioctl.h"

#include <linux/videodev2.h>
#include <sys/ioctl.h>

#include <cerrno>
#include <cstring>

namespace mogao {
namespace {

// The control's description, or nullopt if the device lacks it (or has it disabled).
std::optional<v4l2_query_ext_ctrl> query(int fd, std::uint32_t id) {
    v4l2_query_ext_ctrl q{};
    q.id = id;
    if (xioctl(fd, VIDIOC_QUERY_EXT_CTRL, &q) == -1) return std::nullopt;
    if ((q.flags & V4L2_CTRL_FLAG_DISABLED) != 0) return std::nullopt;
    return q;
}

std::optional<long long> get(int fd, std::uint32_t id) {
    v4l2_control c{};
    c.id = id;
    if (xioctl(fd, VIDIOC_G_CTRL, &c) == -1) return std::nullopt;
    return c.value;
}

bool menu_has(int fd, std::uint32_t id, std::uint32_t index) {
    v4l2_querymenu m{};
    m.id = id;
    m.index = index;
    return xioctl(fd, VIDIOC_QUERYMENU, &m) == 0;
}

// One setting: its automatic switch and its value control.
struct Binding {
    std::uint32_t auto_id;
    std::uint32_t value_id;
    double unit;  // setting units per device unit
    const char* unit_name;
    const char* value_cid;  // for messages
};

class Applier {
public:
    Applier(int fd, const std::string& device, std::string* skipped) : fd_(fd), device_(device), skipped_(skipped) {}

    Status set(std::uint32_t id, long long value, const ControlSetting& s, const char* cid) {
        v4l2_control c{};
        c.id = id;
        c.value = static_cast<std::int32_t>(value);
        if (xioctl(fd_, VIDIOC_S_CTRL, &c) == -1) {
            const int code = errno;
            return make_error(code, device_ + ": " + s.name + ": VIDIOC_S_CTRL " + cid + " = " + std::to_string(value) +
                                        ": " + std::strerror(code));
        }
        return {};
    }

    Status missing(const ControlSetting& s, const std::string& what) {
        if (s.required) {
            return make_error(ENOTSUP, device_ + ": " + s.name + " = " + describe(s) + ": the device has no " + what);
        }
        note(s.name + " (no " + what + ")");
        return {};
    }

    void note(const std::string& text) {
        if (skipped_ != nullptr) *skipped_ += (skipped_->empty() ? "" : ", ") + text;
    }

    // The automatic switch's value for "on" and "off" (exposure is a menu, the others booleans).
    Status set_auto(const Binding& b, const ControlSetting& s, bool on) {
        if (!query(fd_, b.auto_id)) {
            // No automatic switch: a manual value can still be set; lock and auto cannot be expressed.
            if (s.mode == ControlSetting::Mode::manual) return {};
            return missing(s, std::string("automatic mode control for ") + b.value_cid);
        }
        long long value = on ? 1 : 0;
        if (b.auto_id == V4L2_CID_EXPOSURE_AUTO) {
            value = !on                                            ? V4L2_EXPOSURE_MANUAL
                    : menu_has(fd_, b.auto_id, V4L2_EXPOSURE_AUTO) ? V4L2_EXPOSURE_AUTO
                                                                   : V4L2_EXPOSURE_APERTURE_PRIORITY;
        }
        return set(b.auto_id, value, s, b.auto_id == V4L2_CID_EXPOSURE_AUTO ? "V4L2_CID_EXPOSURE_AUTO" : "auto");
    }

    Status apply(const Binding& b, const ControlSetting& s) {
        using Mode = ControlSetting::Mode;
        if (s.mode == Mode::keep) return {};
        if (s.mode == Mode::automatic) return set_auto(b, s, true);
        const auto value_ctrl = query(fd_, b.value_id);
        if (!value_ctrl && s.mode == Mode::manual) return missing(s, b.value_cid);
        // Lock: read what the automatic loop reached before switching it off.
        const std::optional<long long> reached = s.mode == Mode::lock ? get(fd_, b.value_id) : std::nullopt;
        long long target = 0;
        if (s.mode == Mode::manual) {
            const ControlRange range{value_ctrl->minimum, value_ctrl->maximum,
                                     static_cast<long long>(value_ctrl->step)};
            auto v = to_device_value(s.name, s.value, range, b.unit, b.unit_name);
            if (!v && s.required) {
                return make_error(EINVAL, device_ + ": " + v.error().message + " (" + b.value_cid + ")");
            }
            if (!v) {  // a default the device cannot reach: the nearest it can, noted for description()
                const double wanted = s.value / b.unit;
                target = wanted < static_cast<double>(range.minimum) ? range.minimum : range.maximum;
                note(s.name + " clamped to " + std::to_string(static_cast<double>(target) * b.unit) + " " +
                     b.unit_name);
            } else {
                target = *v;
            }
        }
        if (Status st = set_auto(b, s, false); !st) return st;
        if (s.mode == Mode::lock) {
            if (!reached || !value_ctrl) return {};  // the switch alone holds the value
            target = *reached;
        }
        return set(b.value_id, target, s, b.value_cid);
    }

private:
    int fd_;
    const std::string& device_;
    std::string* skipped_;
};

constexpr Binding kExposure{V4L2_CID_EXPOSURE_AUTO, V4L2_CID_EXPOSURE_ABSOLUTE, 100.0, "us",
                            "V4L2_CID_EXPOSURE_ABSOLUTE"};
constexpr Binding kGain{V4L2_CID_AUTOGAIN, V4L2_CID_GAIN, 1.0, "", "V4L2_CID_GAIN"};
constexpr Binding kWhiteBalance{V4L2_CID_AUTO_WHITE_BALANCE, V4L2_CID_WHITE_BALANCE_TEMPERATURE, 1.0, "K",
                                "V4L2_CID_WHITE_BALANCE_TEMPERATURE"};

}  // namespace

Status apply_v4l2_controls(int fd, const std::string& device, const CameraControls& controls, std::string* skipped) {
    Applier applier(fd, device, skipped);
    if (Status s = applier.apply(kExposure, controls.exposure); !s) return s;
    if (controls.exposure.mode == ControlSetting::Mode::manual ||
        controls.exposure.mode == ControlSetting::Mode::lock) {
        // Best effort: a UVC camera with auto priority on may still stretch frames in the dark.
        if (query(fd, V4L2_CID_EXPOSURE_AUTO_PRIORITY)) {
            v4l2_control c{V4L2_CID_EXPOSURE_AUTO_PRIORITY, 0};
            (void)xioctl(fd, VIDIOC_S_CTRL, &c);
        }
    }
    if (Status s = applier.apply(kGain, controls.gain); !s) return s;
    return applier.apply(kWhiteBalance, controls.white_balance);
}

CameraControlValues read_v4l2_controls(int fd) {
    CameraControlValues v;
    const auto read = [fd](std::uint32_t id) -> std::optional<long long> {
        if (!query(fd, id)) return std::nullopt;
        return get(fd, id);
    };
    if (const auto e = read(V4L2_CID_EXPOSURE_AUTO)) v.auto_exposure = *e != V4L2_EXPOSURE_MANUAL;
    if (const auto e = read(V4L2_CID_EXPOSURE_ABSOLUTE)) v.exposure_us = static_cast<double>(*e) * 100.0;
    if (const auto g = read(V4L2_CID_AUTOGAIN)) v.auto_gain = *g != 0;
    if (const auto g = read(V4L2_CID_GAIN)) v.gain = static_cast<double>(*g);
    if (const auto w = read(V4L2_CID_AUTO_WHITE_BALANCE)) v.auto_white_balance = *w != 0;
    if (const auto w = read(V4L2_CID_WHITE_BALANCE_TEMPERATURE)) v.white_balance_k = static_cast<double>(*w);
    return v;
}

}  // namespace mogao
