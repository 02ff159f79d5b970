// SPDX-License-Identifier: Apache-2.0
#include "drivers/camera/v4l2_info.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>

#include <cerrno>
#include <cstring>
#include <sstream>

#include "common/unique_fd.h"
#include "drivers/camera/pixel_format.h"
#include "drivers/camera/v4l2_ioctl.h"

namespace mogao {
namespace {

std::string text_of(const std::uint8_t* bytes, std::size_t size) {
    const auto* chars = reinterpret_cast<const char*>(bytes);
    return std::string(chars, strnlen(chars, size));
}

std::vector<double> frame_rates(int fd, std::uint32_t fourcc, int width, int height) {
    std::vector<double> rates;
    for (std::uint32_t i = 0; i < 16; ++i) {
        v4l2_frmivalenum iv{};
        iv.index = i;
        iv.pixel_format = fourcc;
        iv.width = static_cast<std::uint32_t>(width);
        iv.height = static_cast<std::uint32_t>(height);
        if (xioctl(fd, VIDIOC_ENUM_FRAMEINTERVALS, &iv) == -1) break;
        const v4l2_fract f = iv.type == V4L2_FRMIVAL_TYPE_DISCRETE ? iv.discrete : iv.stepwise.min;
        if (f.numerator != 0) rates.push_back(static_cast<double>(f.denominator) / f.numerator);
        if (iv.type != V4L2_FRMIVAL_TYPE_DISCRETE) break;
    }
    return rates;
}

std::vector<V4l2FrameSize> frame_sizes(int fd, std::uint32_t fourcc) {
    std::vector<V4l2FrameSize> sizes;
    for (std::uint32_t i = 0; i < 64; ++i) {
        v4l2_frmsizeenum fs{};
        fs.index = i;
        fs.pixel_format = fourcc;
        if (xioctl(fd, VIDIOC_ENUM_FRAMESIZES, &fs) == -1) break;
        V4l2FrameSize s;
        if (fs.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
            s.min_width = s.max_width = static_cast<int>(fs.discrete.width);
            s.min_height = s.max_height = static_cast<int>(fs.discrete.height);
            s.frame_rates = frame_rates(fd, fourcc, s.min_width, s.min_height);
            sizes.push_back(s);
            continue;
        }
        s.stepwise = true;
        s.min_width = static_cast<int>(fs.stepwise.min_width);
        s.min_height = static_cast<int>(fs.stepwise.min_height);
        s.max_width = static_cast<int>(fs.stepwise.max_width);
        s.max_height = static_cast<int>(fs.stepwise.max_height);
        s.step_width = static_cast<int>(fs.stepwise.step_width);
        s.step_height = static_cast<int>(fs.stepwise.step_height);
        sizes.push_back(s);
        break;  // stepwise and continuous have index 0 only
    }
    return sizes;
}

const char* type_name(std::uint32_t type) {
    switch (type) {
        case V4L2_CTRL_TYPE_INTEGER:
            return "int";
        case V4L2_CTRL_TYPE_BOOLEAN:
            return "bool";
        case V4L2_CTRL_TYPE_MENU:
            return "menu";
        case V4L2_CTRL_TYPE_INTEGER_MENU:
            return "int menu";
        case V4L2_CTRL_TYPE_BUTTON:
            return "button";
        case V4L2_CTRL_TYPE_INTEGER64:
            return "int64";
        case V4L2_CTRL_TYPE_CTRL_CLASS:
            return "class";
        case V4L2_CTRL_TYPE_BITMASK:
            return "bitmask";
        case V4L2_CTRL_TYPE_STRING:
            return "string";
        default:
            return "other";
    }
}

V4l2ControlInfo control_info(int fd, const v4l2_query_ext_ctrl& q) {
    V4l2ControlInfo c;
    c.id = q.id;
    c.name = text_of(reinterpret_cast<const std::uint8_t*>(q.name), sizeof q.name);
    c.type = type_name(q.type);
    c.minimum = q.minimum;
    c.maximum = q.maximum;
    c.step = static_cast<long long>(q.step);
    c.default_value = q.default_value;
    c.inactive = (q.flags & V4L2_CTRL_FLAG_INACTIVE) != 0;
    c.read_only = (q.flags & V4L2_CTRL_FLAG_READ_ONLY) != 0;
    const bool simple = q.type == V4L2_CTRL_TYPE_INTEGER || q.type == V4L2_CTRL_TYPE_BOOLEAN ||
                        q.type == V4L2_CTRL_TYPE_MENU || q.type == V4L2_CTRL_TYPE_INTEGER_MENU ||
                        q.type == V4L2_CTRL_TYPE_BITMASK;
    if (simple && (q.flags & V4L2_CTRL_FLAG_WRITE_ONLY) == 0) {
        v4l2_control v{};
        v.id = q.id;
        if (xioctl(fd, VIDIOC_G_CTRL, &v) == 0) {
            c.has_value = true;
            c.value = v.value;
        }
    }
    if (q.type == V4L2_CTRL_TYPE_MENU || q.type == V4L2_CTRL_TYPE_INTEGER_MENU) {
        for (long long i = q.minimum; i <= q.maximum && i - q.minimum < 64; ++i) {
            v4l2_querymenu m{};
            m.id = q.id;
            m.index = static_cast<std::uint32_t>(i);
            if (xioctl(fd, VIDIOC_QUERYMENU, &m) == -1) continue;  // a gap: not offered
            c.menu.push_back(std::to_string(i) + ": " +
                             (q.type == V4L2_CTRL_TYPE_MENU
                                  ? text_of(reinterpret_cast<const std::uint8_t*>(m.name), sizeof m.name)
                                  : std::to_string(m.value)));
        }
    }
    return c;
}

std::vector<V4l2ControlInfo> controls_of(int fd) {
    std::vector<V4l2ControlInfo> controls;
    v4l2_query_ext_ctrl q{};
    q.id = V4L2_CTRL_FLAG_NEXT_CTRL | V4L2_CTRL_FLAG_NEXT_COMPOUND;
    for (int n = 0; n < 1024 && xioctl(fd, VIDIOC_QUERY_EXT_CTRL, &q) == 0; ++n) {
        if ((q.flags & V4L2_CTRL_FLAG_DISABLED) == 0 && q.type != V4L2_CTRL_TYPE_CTRL_CLASS) {
            controls.push_back(control_info(fd, q));
        }
        q.id |= V4L2_CTRL_FLAG_NEXT_CTRL | V4L2_CTRL_FLAG_NEXT_COMPOUND;
    }
    return controls;
}

Result<V4l2DeviceInfo> open_and_query_caps(const std::string& device, UniqueFd& fd) {
    fd = UniqueFd(::open(device.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC));
    if (!fd.valid()) return errno_error("open " + device);
    v4l2_capability cap{};
    if (xioctl(fd.get(), VIDIOC_QUERYCAP, &cap) == -1) {
        const int code = errno;
        return make_error(code, device + ": VIDIOC_QUERYCAP: " + std::strerror(code) + " (not a V4L2 device?)");
    }
    const std::uint32_t caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) != 0 ? cap.device_caps : cap.capabilities;
    if ((caps & (V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_VIDEO_CAPTURE_MPLANE)) == 0) {
        return make_error(ENODEV,
                          device + " (" + text_of(cap.driver, sizeof cap.driver) + "): not a video capture node");
    }
    V4l2DeviceInfo info;
    info.device = device;
    info.driver = text_of(cap.driver, sizeof cap.driver);
    info.card = text_of(cap.card, sizeof cap.card);
    info.bus = text_of(cap.bus_info, sizeof cap.bus_info);
    info.multiplanar = (caps & V4L2_CAP_VIDEO_CAPTURE) == 0;
    return info;
}

}  // namespace

Result<V4l2DeviceInfo> query_v4l2_device(const std::string& device) {
    UniqueFd fd;
    auto info = open_and_query_caps(device, fd);
    if (!info) return info.error();
    const std::uint32_t type = info->multiplanar ? V4L2_BUF_TYPE_VIDEO_CAPTURE_MPLANE : V4L2_BUF_TYPE_VIDEO_CAPTURE;
    for (std::uint32_t i = 0; i < 256; ++i) {
        v4l2_fmtdesc desc{};
        desc.index = i;
        desc.type = type;
        if (xioctl(fd.get(), VIDIOC_ENUM_FMT, &desc) == -1) break;
        V4l2FormatInfo f;
        f.fourcc = desc.pixelformat;
        f.description = text_of(desc.description, sizeof desc.description);
        f.compressed = (desc.flags & V4L2_FMT_FLAG_COMPRESSED) != 0;
        f.sizes = frame_sizes(fd.get(), desc.pixelformat);
        info->formats.push_back(std::move(f));
    }
    info->controls = controls_of(fd.get());
    return info;
}

std::vector<V4l2DeviceInfo> list_v4l2_devices() {
    std::vector<V4l2DeviceInfo> devices;
    for (int i = 0; i < 64; ++i) {
        UniqueFd fd;
        auto info = open_and_query_caps("/dev/video" + std::to_string(i), fd);
        if (info) devices.push_back(std::move(info).value());
    }
    return devices;
}

std::string format_v4l2_info(const V4l2DeviceInfo& info) {
    std::ostringstream out;
    out << info.device << ": driver " << info.driver << ", card \"" << info.card << "\", bus " << info.bus << ", "
        << (info.multiplanar ? "multi-planar" : "single-planar") << " capture\n";
    out << "formats:\n";
    for (const V4l2FormatInfo& f : info.formats) {
        out << "  " << fourcc_name(f.fourcc) << "  \"" << f.description << "\"" << (f.compressed ? " compressed" : "")
            << "\n";
        for (const V4l2FrameSize& s : f.sizes) {
            if (s.stepwise) {
                out << "    " << s.min_width << "x" << s.min_height << " .. " << s.max_width << "x" << s.max_height
                    << " step " << s.step_width << "x" << s.step_height << "\n";
                continue;
            }
            out << "    " << s.min_width << "x" << s.min_height;
            for (std::size_t r = 0; r < s.frame_rates.size(); ++r) out << (r == 0 ? " @ " : ", ") << s.frame_rates[r];
            out << (s.frame_rates.empty() ? "\n" : " fps\n");
        }
    }
    out << "controls:\n";
    for (const V4l2ControlInfo& c : info.controls) {
        out << "  " << c.name << " (" << c.type << ", 0x" << std::hex << c.id << std::dec << ") [" << c.minimum << ", "
            << c.maximum << "] step " << c.step << " default " << c.default_value;
        if (c.has_value) out << " value " << c.value;
        if (c.inactive) out << " inactive";
        if (c.read_only) out << " read-only";
        out << "\n";
        for (const std::string& item : c.menu) out << "      " << item << "\n";
    }
    return out.str();
}

}  // namespace mogao
