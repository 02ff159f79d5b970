// SPDX-License-Identifier: Apache-2.0
// LibcameraCapture: the pure helpers and the build-without-libcamera path run in every build; the
// streaming test needs a camera libcamera can see and otherwise skips ("no libcamera camera; ...",
// the binary exits 77 if nothing else ran).
#include "drivers/camera/libcamera_capture.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <thread>

#include "drivers/camera/pixel_format.h"

namespace mogao {
namespace {

#ifdef MOGAO_HAVE_LIBCAMERA
constexpr bool kBuiltWithLibcamera = true;
#else
constexpr bool kBuiltWithLibcamera = false;
#endif

TEST(LibcameraHelpers, FourccsMatchLibcamera) {
    // libcamera's formats::R8 is fourcc('R', '8', ' ', ' '), i.e. "R8  " little-endian.
    EXPECT_EQ(libcamera_fourcc(CaptureFormat::grey), 0x20203852u);
    EXPECT_EQ(libcamera_fourcc(CaptureFormat::yuyv), 0x56595559u);
    EXPECT_EQ(libcamera_fourcc(CaptureFormat::mjpeg), 0x47504a4du);
    EXPECT_EQ(libcamera_fourcc(CaptureFormat::image_file), 0u);
}

TEST(LibcameraHelpers, DefaultConfigIsValid) { EXPECT_TRUE(check_libcamera_config(LibcameraConfig{}).ok()); }

TEST(LibcameraHelpers, ConfigRejectsEachBadField) {
    const auto expect_bad = [](LibcameraConfig c, const std::string& field) {
        const Status s = check_libcamera_config(c);
        ASSERT_FALSE(s.ok()) << field;
        EXPECT_EQ(s.code(), EINVAL);
        EXPECT_NE(s.error().message.find(field), std::string::npos) << s.error().message;
    };
    LibcameraConfig c;
    c.width = 0;
    expect_bad(c, "width x height");
    c = {};
    c.height = kMaxCaptureDimension + 1;
    expect_bad(c, "width x height");
    c = {};
    c.formats.clear();
    expect_bad(c, "formats is empty");
    c = {};
    c.formats = {CaptureFormat::image_file};
    expect_bad(c, "formats:");
    c = {};
    c.buffer_count = 1;
    expect_bad(c, "buffer_count 1 outside [2, 4]");
    c.buffer_count = 5;
    expect_bad(c, "buffer_count 5");
    c = {};
    c.timeout_ms = 0;
    expect_bad(c, "timeout_ms");
    c = {};
    c.buffer_count = 2;
    EXPECT_TRUE(check_libcamera_config(c).ok());
    c.buffer_count = 4;
    EXPECT_TRUE(check_libcamera_config(c).ok());
}

TEST(LibcameraHelpers, ChoosesFirstPreferredOfferedFormat) {
    const std::uint32_t r8 = libcamera_fourcc(CaptureFormat::grey);
    const std::uint32_t yuyv = libcamera_fourcc(CaptureFormat::yuyv);
    const std::uint32_t mjpg = libcamera_fourcc(CaptureFormat::mjpeg);
    const std::uint32_t nv12 = 0x3231564eu;
    const std::vector<CaptureFormat> all{CaptureFormat::grey, CaptureFormat::yuyv, CaptureFormat::mjpeg};
    EXPECT_EQ(choose_libcamera_format(all, {mjpg, yuyv, nv12}), CaptureFormat::yuyv);  // preference, not offer order
    EXPECT_EQ(choose_libcamera_format(all, {mjpg, r8}), CaptureFormat::grey);
    EXPECT_EQ(choose_libcamera_format({CaptureFormat::mjpeg, CaptureFormat::yuyv}, {yuyv, mjpg}),
              CaptureFormat::mjpeg);
    EXPECT_EQ(choose_libcamera_format(all, {nv12}), std::nullopt);
    EXPECT_EQ(choose_libcamera_format(all, {}), std::nullopt);
    EXPECT_EQ(choose_libcamera_format({CaptureFormat::image_file}, {0u}), std::nullopt);  // 0 is no format
}

TEST(LibcameraHelpers, TimestampPrefersSensorTimestamp) {
    EXPECT_EQ(libcamera_frame_timestamp_ns(std::int64_t{123'456'789}, 999), 123'456'789);
    EXPECT_EQ(libcamera_frame_timestamp_ns(std::nullopt, 999), 999);
    EXPECT_EQ(libcamera_frame_timestamp_ns(std::int64_t{0}, 999), 999);  // an unset control
}

TEST(LibcameraBuild, BuiltInMatchesTheMacro) { EXPECT_EQ(libcamera_built_in(), kBuiltWithLibcamera); }

TEST(LibcameraBuild, OpenReportsHowItWasBuilt) {
    auto cam = LibcameraCapture::open(LibcameraConfig{});
    if (!kBuiltWithLibcamera) {
        ASSERT_FALSE(cam.ok());
        EXPECT_EQ(cam.code(), ENOTSUP);
        EXPECT_NE(cam.error().message.find("built without libcamera"), std::string::npos) << cam.error().message;
        return;
    }
    if (cam.ok()) GTEST_SKIP() << "a libcamera camera is present: " << (*cam)->description();
    // No camera (or libcamera cannot start here): a clear error naming libcamera, never an abort.
    EXPECT_NE(cam.error().message.find("libcamera"), std::string::npos) << cam.error().message;
    EXPECT_EQ(cam.error().message.find("built without libcamera"), std::string::npos) << cam.error().message;
    std::printf("libcamera open without camera: %s (code %d)\n", cam.error().message.c_str(), cam.code());
}

TEST(LibcameraBuild, BadConfigIsRejectedBeforeLibcamera) {
    LibcameraConfig c;
    c.buffer_count = 9;
    auto cam = LibcameraCapture::open(c);
    ASSERT_FALSE(cam.ok());
    // The disabled build reports the build first; the real one validates before starting libcamera.
    EXPECT_EQ(cam.code(), kBuiltWithLibcamera ? EINVAL : ENOTSUP) << cam.error().message;
}

TEST(LibcameraBuild, UnknownCameraIdIsNamed) {
    if (!kBuiltWithLibcamera) GTEST_SKIP() << "built without libcamera";
    LibcameraConfig c;
    c.camera_id = "/base/no/such/camera";
    auto cam = LibcameraCapture::open(c);
    ASSERT_FALSE(cam.ok());
    EXPECT_NE(cam.error().message.find("libcamera"), std::string::npos) << cam.error().message;
    if (cam.code() == ENODEV) {
        EXPECT_NE(cam.error().message.find("/base/no/such/camera"), std::string::npos) << cam.error().message;
    }
}

TEST(LibcameraCamera, StreamsNewestFrames) {
    if (!kBuiltWithLibcamera) GTEST_SKIP() << "no libcamera camera; built without libcamera";
    LibcameraConfig config;
    config.width = 640;
    config.height = 480;
    auto cam = LibcameraCapture::open(config);
    if (!cam) GTEST_SKIP() << "no libcamera camera; " << cam.error().message;
    EXPECT_GE((*cam)->buffer_count(), 2);
    // While one is open a second must be refused (libcamera 0.0.x aborts on a second CameraManager).
    auto second_open = LibcameraCapture::open(config);
    ASSERT_FALSE(second_open.ok());
    EXPECT_EQ(second_open.code(), EBUSY);

    auto first = (*cam)->next_frame();
    ASSERT_TRUE(first.ok()) << first.error().message;
    std::this_thread::sleep_for(std::chrono::milliseconds(150));  // let frames queue up
    auto second = (*cam)->next_frame();
    ASSERT_TRUE(second.ok()) << second.error().message;
    EXPECT_EQ(second->image.width, (*cam)->size().width);
    EXPECT_EQ(second->image.height, (*cam)->size().height);
    EXPECT_TRUE(second->image.valid());
    EXPECT_EQ(second->format, (*cam)->format());
    EXPECT_GT(second->timestamp_ns, first->timestamp_ns);
    EXPECT_GE(second->sequence - first->sequence, std::uint64_t{second->skipped} + 1);
}

}  // namespace
}  // namespace mogao
