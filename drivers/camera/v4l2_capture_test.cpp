// SPDX-License-Identifier: Apache-2.0
// Against a real kernel V4L2 driver: vivid (modprobe vivid), the kernel's virtual capture device.
// Without one, the device tests skip with a message (the binary exits 77 if nothing else ran);
// the error-path tests need no device and run everywhere.
#include "drivers/camera/v4l2_capture.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <optional>
#include <thread>

#include "common/unique_fd.h"
#include "drivers/camera/pixel_format.h"
#include "drivers/camera/v4l2_info.h"

namespace mogao {
namespace {

// The first /dev/videoN whose driver is vivid and which can capture (single-planar, or with
// `multiplanar` the multi-planar API: vivid's module option multiplanar=2), or nothing.
std::optional<std::string> find_vivid(bool multiplanar = false) {
    for (int i = 0; i < 64; ++i) {
        const std::string path = "/dev/video" + std::to_string(i);
        UniqueFd fd(::open(path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC));
        if (!fd.valid()) continue;
        v4l2_capability cap{};
        if (::ioctl(fd.get(), VIDIOC_QUERYCAP, &cap) != 0) continue;
        const std::uint32_t caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) != 0 ? cap.device_caps : cap.capabilities;
        if (std::strcmp(reinterpret_cast<const char*>(cap.driver), "vivid") == 0 &&
            (caps & (multiplanar ? V4L2_CAP_VIDEO_CAPTURE_MPLANE : V4L2_CAP_VIDEO_CAPTURE)) != 0) {
            return path;
        }
    }
    return std::nullopt;
}

#define REQUIRE_VIVID(var)         \
    const auto var = find_vivid(); \
    if (!var) GTEST_SKIP() << "no vivid capture device in /dev/video* (load it with modprobe vivid)"

#define REQUIRE_VIVID_MPLANE(var)      \
    const auto var = find_vivid(true); \
    if (!var) GTEST_SKIP() << "no multi-planar vivid capture device (modprobe vivid n_devs=2 multiplanar=1,2)"

void expect_streams(const std::string& device, CaptureFormat format, bool colour = false) {
    V4l2Config config;
    config.device = device;
    config.width = 640;
    config.height = 480;
    config.formats = {format};
    config.buffer_count = 3;
    config.colour = colour;
    auto cam = V4l2Capture::open(config);
    if (!cam && cam.code() == ENOTSUP) GTEST_SKIP() << cam.error().message;
    ASSERT_TRUE(cam.ok()) << cam.error().message;
    EXPECT_EQ((*cam)->format(), format);
    EXPECT_GE((*cam)->buffer_count(), 2);
    auto first = (*cam)->next_frame();
    ASSERT_TRUE(first.ok()) << first.error().message;
    // Let frames queue up; the next call must still return the newest, having dropped the rest.
    std::this_thread::sleep_for(std::chrono::milliseconds(150));
    auto second = (*cam)->next_frame();
    ASSERT_TRUE(second.ok()) << second.error().message;
    EXPECT_EQ(second->image.width, (*cam)->size().width);
    EXPECT_EQ(second->image.height, (*cam)->size().height);
    EXPECT_TRUE(second->image.valid());
    EXPECT_GT(second->timestamp_ns, first->timestamp_ns);
    EXPECT_EQ(second->clock, TimestampSource::kernel_monotonic);  // vivid stamps CLOCK_MONOTONIC
    // Every frame between the two was either skipped or not yet captured: never delivered twice.
    EXPECT_GE(second->sequence - first->sequence, std::uint64_t{second->skipped} + 1);
    EXPECT_EQ(second->colour.has_value(), colour);
}

// vivid's default test pattern is 75% colour bars (white, yellow, cyan, green, magenta, red, blue,
// black; drivers/media/test-drivers/vivid, tpg "75% Colorbar"): R'G'B' 191 or 0 per channel. The
// bottom rows carry no on-screen text. A wrong plane order, matrix or range moves these by far more
// than the tolerance (chroma subsampling only blurs the bar edges, which are not sampled).
void expect_colour_bars(const std::string& device, CaptureFormat format) {
    V4l2Config config;
    config.device = device;
    config.width = 640;
    config.height = 480;
    config.formats = {format};
    config.colour = true;
    auto cam = V4l2Capture::open(config);
    if (!cam && cam.code() == ENOTSUP) GTEST_SKIP() << cam.error().message;
    ASSERT_TRUE(cam.ok()) << cam.error().message;
    auto frame = (*cam)->next_frame();
    ASSERT_TRUE(frame.ok()) << frame.error().message;
    ASSERT_TRUE(frame->colour.has_value());
    const Rgb8Image& rgb = *frame->colour;
    ASSERT_EQ(rgb.size.width, frame->image.width);
    const int bars[8][3] = {{191, 191, 191}, {191, 191, 0}, {0, 191, 191}, {0, 191, 0},
                            {191, 0, 191},   {191, 0, 0},   {0, 0, 191},   {0, 0, 0}};
    const int y = rgb.size.height - 8;
    for (int i = 0; i < 8; ++i) {
        const int x = (2 * i + 1) * rgb.size.width / 16;
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(rgb.at(x, y)[c], bars[i][c], 12) << (*cam)->description() << ": bar " << i << " channel " << c;
        }
    }
}

TEST(V4l2CaptureVivid, StreamsGrey) {
    REQUIRE_VIVID(device);
    expect_streams(*device, CaptureFormat::grey);
}

TEST(V4l2CaptureVivid, StreamsYuyv) {
    REQUIRE_VIVID(device);
    expect_streams(*device, CaptureFormat::yuyv);
}

TEST(V4l2CaptureVivid, StreamsYuv420Formats) {
    REQUIRE_VIVID(device);
    for (CaptureFormat f : {CaptureFormat::nv12, CaptureFormat::nv21, CaptureFormat::yuv420, CaptureFormat::yvu420}) {
        SCOPED_TRACE(pixel_format_name(f));
        expect_streams(*device, f);
    }
}

TEST(V4l2CaptureVivid, ColourFramesShowTheColourBars) {
    REQUIRE_VIVID(device);
    for (CaptureFormat f : {CaptureFormat::yuyv, CaptureFormat::nv12, CaptureFormat::yvu420}) {
        SCOPED_TRACE(pixel_format_name(f));
        expect_colour_bars(*device, f);
    }
}

TEST(V4l2CaptureVivid, StreamsMultiplanarNv12mAndYuv420m) {
    REQUIRE_VIVID_MPLANE(device);
    for (CaptureFormat f : {CaptureFormat::nv12, CaptureFormat::yuv420}) {
        SCOPED_TRACE(pixel_format_name(f));
        expect_streams(*device, f, true);
        expect_colour_bars(*device, f);
        V4l2Config config;
        config.device = *device;
        config.formats = {f};
        auto cam = V4l2Capture::open(config);
        ASSERT_TRUE(cam.ok()) << cam.error().message;
        EXPECT_TRUE((*cam)->multiplanar());
        EXPECT_EQ((*cam)->plane_count(), f == CaptureFormat::nv12 ? 2 : 3) << (*cam)->description();
    }
}

// vivid has AUTOGAIN and GAIN (0..255; under auto gain it changes every second) but no exposure or
// white-balance controls.
TEST(V4l2CaptureVivid, GainIsSetCheckedAndLocked) {
    REQUIRE_VIVID(device);
    V4l2Config config;
    config.device = *device;
    config.controls.gain = {ControlSetting::Mode::manual, 50, true, "[navigation].camera_gain"};
    auto cam = V4l2Capture::open(config);
    ASSERT_TRUE(cam.ok()) << cam.error().message;
    CameraControlValues v = (*cam)->control_values();
    ASSERT_TRUE(v.gain && v.auto_gain);
    EXPECT_EQ(*v.gain, 50);
    EXPECT_FALSE(*v.auto_gain);
    cam = Result<std::unique_ptr<V4l2Capture>>(make_error(EIO, "closed"));

    config.controls.gain.value = 1000;
    cam = V4l2Capture::open(config);
    ASSERT_FALSE(cam.ok());
    EXPECT_EQ(cam.code(), EINVAL);
    EXPECT_NE(cam.error().message.find("[navigation].camera_gain = 1000 is outside the device's range [0, 255]"),
              std::string::npos)
        << cam.error().message;

    config.controls.gain.required = false;  // a default: clamped into the range, and said so
    cam = V4l2Capture::open(config);
    ASSERT_TRUE(cam.ok()) << cam.error().message;
    EXPECT_EQ((*cam)->control_values().gain, 255.0);
    EXPECT_NE((*cam)->description().find("[navigation].camera_gain clamped to 255"), std::string::npos)
        << (*cam)->description();
    cam = Result<std::unique_ptr<V4l2Capture>>(make_error(EIO, "closed"));

    config.controls.gain = {ControlSetting::Mode::automatic, 0, true, "gain"};
    cam = V4l2Capture::open(config);
    ASSERT_TRUE(cam.ok()) << cam.error().message;
    EXPECT_TRUE(*(*cam)->control_values().auto_gain);
    ControlSetting lock{ControlSetting::Mode::lock, 0, true, "gain"};
    CameraControls controls;
    controls.gain = lock;
    ASSERT_TRUE((*cam)->apply_controls(controls).ok());
    v = (*cam)->control_values();
    EXPECT_FALSE(*v.auto_gain);
    std::this_thread::sleep_for(std::chrono::milliseconds(1100));  // auto gain would have moved by now
    EXPECT_EQ((*cam)->control_values().gain, v.gain);
}

TEST(V4l2CaptureVivid, MissingControlsAreErrorsOnlyWhenRequired) {
    REQUIRE_VIVID(device);
    V4l2Config config;
    config.device = *device;
    config.controls.exposure = {ControlSetting::Mode::manual, 8000, false, "exposure_us"};
    auto cam = V4l2Capture::open(config);
    ASSERT_TRUE(cam.ok()) << cam.error().message;
    EXPECT_NE((*cam)->description().find("controls not on this device: exposure_us"), std::string::npos)
        << (*cam)->description();
    cam = Result<std::unique_ptr<V4l2Capture>>(make_error(EIO, "closed"));
    config.controls.exposure.required = true;
    cam = V4l2Capture::open(config);
    ASSERT_FALSE(cam.ok());
    EXPECT_EQ(cam.code(), ENOTSUP);
    EXPECT_NE(cam.error().message.find("exposure_us = manual 8000: the device has no V4L2_CID_EXPOSURE_ABSOLUTE"),
              std::string::npos)
        << cam.error().message;
}

// What `mogao-camera info` prints: vivid's formats with sizes, and its gain control with its range.
TEST(V4l2CaptureVivid, InfoListsFormatsSizesAndControlRanges) {
    REQUIRE_VIVID(device);
    auto info = query_v4l2_device(*device);
    ASSERT_TRUE(info.ok()) << info.error().message;
    EXPECT_EQ(info->driver, "vivid");
    bool nv12 = false;
    for (const V4l2FormatInfo& f : info->formats) {
        if (f.fourcc == V4L2_PIX_FMT_NV12) nv12 = !f.sizes.empty();
    }
    EXPECT_TRUE(nv12) << format_v4l2_info(*info);
    bool gain = false;
    for (const V4l2ControlInfo& c : info->controls) {
        if (c.id == V4L2_CID_GAIN) gain = c.minimum == 0 && c.maximum == 255 && c.type == "int";
    }
    EXPECT_TRUE(gain) << format_v4l2_info(*info);
    bool listed = false;
    for (const V4l2DeviceInfo& d : list_v4l2_devices()) listed = listed || d.device == *device;
    EXPECT_TRUE(listed);
}

TEST(V4l2CaptureVivid, StreamsMjpegWhenOffered) {
    REQUIRE_VIVID(device);
    expect_streams(*device, CaptureFormat::mjpeg);
}

TEST(V4l2CaptureErrors, MissingDeviceIsEnoent) {
    V4l2Config config;
    config.device = "/dev/mogao-no-such-camera";
    auto cam = V4l2Capture::open(config);
    ASSERT_FALSE(cam.ok());
    EXPECT_EQ(cam.code(), ENOENT);
    EXPECT_NE(cam.error().message.find("/dev/mogao-no-such-camera"), std::string::npos) << cam.error().message;
}

TEST(V4l2CaptureErrors, NonV4l2FileIsRefusedByQuerycap) {
    V4l2Config config;
    config.device = "/dev/null";
    auto cam = V4l2Capture::open(config);
    ASSERT_FALSE(cam.ok());
    EXPECT_EQ(cam.code(), ENOTTY);
    EXPECT_NE(cam.error().message.find("VIDIOC_QUERYCAP"), std::string::npos) << cam.error().message;
}

TEST(V4l2CaptureErrors, BadConfigNamesFieldAndLimit) {
    V4l2Config config;
    config.buffer_count = 9;
    auto cam = V4l2Capture::open(config);
    ASSERT_FALSE(cam.ok());
    EXPECT_EQ(cam.code(), EINVAL);
    EXPECT_NE(cam.error().message.find("buffer_count 9 outside [2, 4]"), std::string::npos) << cam.error().message;

    config = {};
    config.formats = {CaptureFormat::image_file};
    cam = V4l2Capture::open(config);
    ASSERT_FALSE(cam.ok());
    EXPECT_NE(cam.error().message.find("formats"), std::string::npos) << cam.error().message;
}

}  // namespace
}  // namespace mogao
