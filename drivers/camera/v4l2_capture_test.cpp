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

namespace mogao {
namespace {

// The first /dev/videoN whose driver is vivid and which can capture, or nothing.
std::optional<std::string> find_vivid() {
    for (int i = 0; i < 64; ++i) {
        const std::string path = "/dev/video" + std::to_string(i);
        UniqueFd fd(::open(path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC));
        if (!fd.valid()) continue;
        v4l2_capability cap{};
        if (::ioctl(fd.get(), VIDIOC_QUERYCAP, &cap) != 0) continue;
        const std::uint32_t caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) != 0 ? cap.device_caps : cap.capabilities;
        if (std::strcmp(reinterpret_cast<const char*>(cap.driver), "vivid") == 0 &&
            (caps & V4L2_CAP_VIDEO_CAPTURE) != 0) {
            return path;
        }
    }
    return std::nullopt;
}

#define REQUIRE_VIVID(var)         \
    const auto var = find_vivid(); \
    if (!var) GTEST_SKIP() << "no vivid capture device in /dev/video* (load it with modprobe vivid)"

void expect_streams(const std::string& device, CaptureFormat format) {
    V4l2Config config;
    config.device = device;
    config.width = 640;
    config.height = 480;
    config.formats = {format};
    config.buffer_count = 3;
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
}

TEST(V4l2CaptureVivid, StreamsGrey) {
    REQUIRE_VIVID(device);
    expect_streams(*device, CaptureFormat::grey);
}

TEST(V4l2CaptureVivid, StreamsYuyv) {
    REQUIRE_VIVID(device);
    expect_streams(*device, CaptureFormat::yuyv);
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
