// SPDX-License-Identifier: Apache-2.0
// LibcameraCapture: the pure helpers and the build-without-libcamera path run in every build; the
// streaming tests need a camera libcamera can see and otherwise skip ("no libcamera camera; ...",
// the binary exits 77 if nothing else ran). With MOGAO_REQUIRE_LIBCAMERA_CAMERA=1 in the
// environment a missing camera FAILS instead: the appliance's QEMU test (image/test/selftest.sh)
// sets it, because its guest has vimc (the kernel's virtual media-controller camera, streamed
// through libcamera's vimc pipeline handler and IPA) and a skip there would hide a regression.
// vimc offers packed RGB only (libcamera RGB888/BGR888) and its sensor shows the test pattern
// generator's 75 % colour bars, which the format test uses as ground truth for the channel order.
#include "drivers/camera/libcamera_capture.h"

#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <string_view>
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
    EXPECT_EQ(libcamera_fourcc(CaptureFormat::rgb24), 0x34324742u);  // "BG24": DRM BGR888, bytes R G B
    EXPECT_EQ(libcamera_fourcc(CaptureFormat::bgr24), 0x34324752u);  // "RG24": DRM RGB888, bytes B G R
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
    EXPECT_EQ(choose_libcamera_format({CaptureFormat::mjpeg, CaptureFormat::yuyv}, {yuyv, mjpg}), CaptureFormat::mjpeg);
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

TEST(LibcameraBuild, DescribeReportsHowItWasBuilt) {
    auto text = describe_libcamera_cameras("");
    if (!kBuiltWithLibcamera) {
        ASSERT_FALSE(text.ok());
        EXPECT_EQ(text.code(), ENOTSUP);
        return;
    }
    if (text.ok()) GTEST_SKIP() << "a libcamera camera is present:\n" << *text;
    EXPECT_EQ(text.code(), ENODEV) << text.error().message;
    EXPECT_NE(text.error().message.find("libcamera"), std::string::npos) << text.error().message;
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

// Opens `config`; no camera is a skip, or a failure where a camera must exist (see the top).
Result<std::unique_ptr<LibcameraCapture>> open_or_skip(const LibcameraConfig& config, bool& skip) {
    skip = false;
    if (!kBuiltWithLibcamera) {
        skip = true;
        return make_error(ENOTSUP, "built without libcamera");
    }
    auto cam = LibcameraCapture::open(config);
    const char* required = std::getenv("MOGAO_REQUIRE_LIBCAMERA_CAMERA");
    if (!cam && cam.code() == ENODEV && (required == nullptr || std::string_view(required) != "1")) skip = true;
    return cam;
}

#define OPEN_LIBCAMERA_OR_SKIP(cam, config)                                                                 \
    bool cam##_skip = false;                                                                                \
    auto cam = open_or_skip(config, cam##_skip);                                                            \
    if (cam##_skip) GTEST_SKIP() << "no libcamera camera; " << cam.error().message;                         \
    ASSERT_TRUE(cam.ok()) << "a libcamera camera must be present (MOGAO_REQUIRE_LIBCAMERA_CAMERA=1 or not " \
                             "ENODEV): "                                                                    \
                          << cam.error().message;                                                           \
    std::printf("%s: %s\n", ::testing::UnitTest::GetInstance()->current_test_info()->name(),                \
                (*cam)->description().c_str())

TEST(LibcameraCamera, StreamsNewestFrames) {
    LibcameraConfig config;
    config.width = 640;
    config.height = 480;
    OPEN_LIBCAMERA_OR_SKIP(cam, config);
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
    EXPECT_EQ(second->clock, TimestampSource::kernel_monotonic);
    EXPECT_GT(second->timestamp_ns, first->timestamp_ns);
    EXPECT_GE(second->sequence - first->sequence, std::uint64_t{second->skipped} + 1);
}

// Many more frames than buffers: every request is re-queued, sequences and timestamps only grow,
// no frame is delivered twice, and frames delivered plus frames skipped cover the sequence span
// (a request that was never re-queued would stall the stream: ETIMEDOUT).
TEST(LibcameraCamera, RequeuesOverManyFrames) {
    LibcameraConfig config;
    config.width = 320;
    config.height = 240;
    config.buffer_count = 2;
    config.timeout_ms = 20000;  // TCG (QEMU without KVM) is slow
    OPEN_LIBCAMERA_OR_SKIP(cam, config);
    constexpr int kFrames = 24;  // 6-12 times the buffer count
    std::set<std::uint64_t> sequences;
    std::uint64_t skipped = 0;
    std::optional<CameraFrame> previous;
    std::uint64_t first_sequence = 0;
    for (int i = 0; i < kFrames; ++i) {
        auto frame = (*cam)->next_frame();
        ASSERT_TRUE(frame.ok()) << "frame " << i << ": " << frame.error().message;
        ASSERT_EQ(frame->image.width, (*cam)->size().width);
        ASSERT_EQ(frame->image.height, (*cam)->size().height);
        EXPECT_TRUE(sequences.insert(frame->sequence).second) << "sequence " << frame->sequence << " twice";
        if (previous) {
            EXPECT_GT(frame->sequence, previous->sequence) << "frame " << i;
            EXPECT_GT(frame->timestamp_ns, previous->timestamp_ns) << "frame " << i;
            skipped += frame->skipped;
        } else {
            first_sequence = frame->sequence;
        }
        previous = std::move(frame).value();
    }
    const std::uint64_t span = previous->sequence - first_sequence;
    EXPECT_GE(span, std::uint64_t{kFrames - 1});
    std::printf("%d frames, sequence %llu..%llu, %llu skipped (newest-frame policy)\n", kFrames,
                static_cast<unsigned long long>(first_sequence), static_cast<unsigned long long>(previous->sequence),
                static_cast<unsigned long long>(skipped));
}

// The mean R'G'B' of a small window centred at (x, y).
std::array<double, 3> mean_rgb(const Rgb8Image& image, int x, int y) {
    std::array<double, 3> sum{};
    int n = 0;
    for (int v = y - 2; v <= y + 2; ++v) {
        for (int u = x - 2; u <= x + 2; ++u) {
            const std::uint8_t* p = image.pixels.data() + 3 * (static_cast<std::size_t>(v) * image.size.width + u);
            for (int c = 0; c < 3; ++c) sum[static_cast<std::size_t>(c)] += p[c];
            ++n;
        }
    }
    for (double& c : sum) c /= n;
    return sum;
}

// Each packed RGB format the camera offers, in colour: the frame's grey is exactly the BT.601 luma
// of its colour frame, and the first of the test pattern's bars (v4l2-tpg's 75 % colour bars) is a
// neutral 75 % white in both byte orders. The other bars are printed, not checked: through
// libcamera 0.0.3 and the 6.1 kernel's vimc (Bayer sensor, debayer, x3 scaler) they do not come out
// as the pattern's colours (yellow measured R' 57 G' 80 B' 38 at 324x240; the same in both byte
// orders), so vimc cannot be the ground truth for the channel order; pixel_format_test checks
// convert_rgb24's order on known bytes.
TEST(LibcameraCamera, PackedRgbFormatsInColour) {
    int opened = 0;
    for (CaptureFormat format : {CaptureFormat::rgb24, CaptureFormat::bgr24}) {
        LibcameraConfig config;
        config.width = 324;  // vimc in libcamera 0.0.3: multiples of 6 (its x3 scaler)
        config.height = 240;
        config.formats = {format};
        config.colour = true;
        config.timeout_ms = 20000;
        bool skip = false;
        auto cam = open_or_skip(config, skip);
        if (skip) GTEST_SKIP() << "no libcamera camera; " << cam.error().message;
        if (!cam && cam.code() == ENOTSUP) {
            std::printf("%s not offered: %s\n", pixel_format_name(format).c_str(), cam.error().message.c_str());
            continue;
        }
        ASSERT_TRUE(cam.ok()) << cam.error().message;
        ++opened;
        std::printf("%s\n", (*cam)->description().c_str());
        EXPECT_EQ((*cam)->format(), format);
        auto frame = (*cam)->next_frame();
        ASSERT_TRUE(frame.ok()) << frame.error().message;
        ASSERT_TRUE(frame->colour.has_value());
        const Rgb8Image& rgb = *frame->colour;
        ASSERT_EQ(rgb.size.width, (*cam)->size().width);
        ASSERT_EQ(rgb.size.height, (*cam)->size().height);
        GrayImage luma;
        grey_from_rgb(rgb, luma);
        EXPECT_EQ(luma.pixels, frame->image.pixels) << "grey is the BT.601 luma of the colour frame";
        // Bar k spans [k w / 8, (k + 1) w / 8); sample each centre, mid-height.
        const int w = rgb.size.width;
        const int y = rgb.size.height / 2;
        for (int k = 0; k < 8; ++k) {
            const std::array<double, 3> c = mean_rgb(rgb, (2 * k + 1) * w / 16, y);
            std::printf("  %s bar %d: R' %.0f G' %.0f B' %.0f\n", pixel_format_name(format).c_str(), k, c[0], c[1],
                        c[2]);
            if (k != 0) continue;
            for (double v : c) EXPECT_NEAR(v, 191.0, 24.0) << pixel_format_name(format) << " bar 0 (75 % white)";
        }
    }
    if (opened == 0) GTEST_SKIP() << "the camera offers neither BGR888 nor RGB888";
}

// Exposure and gain through libcamera's AeEnable / ExposureTime / AnalogueGain: a camera without
// them (vimc has only Brightness, Contrast, Saturation) refuses a required setting with ENOTSUP
// naming it, and opens with a default one, naming what it skipped.
TEST(LibcameraCamera, ExposureAndGainControls) {
    LibcameraConfig config;
    config.width = 320;
    config.height = 240;
    config.timeout_ms = 20000;
    config.controls.exposure = {ControlSetting::Mode::manual, 2000.0, true, "exposure_us"};
    config.controls.gain = {ControlSetting::Mode::manual, 2.0, true, "gain"};
    bool skip = false;
    auto strict = open_or_skip(config, skip);
    if (skip) GTEST_SKIP() << "no libcamera camera; " << strict.error().message;
    if (strict.ok()) {
        std::printf("camera has AeEnable/ExposureTime/AnalogueGain: %s\n", (*strict)->description().c_str());
        auto frame = (*strict)->next_frame();
        ASSERT_TRUE(frame.ok()) << frame.error().message;
        return;
    }
    std::printf("required exposure 2000 us, gain 2: %s\n", strict.error().message.c_str());
    EXPECT_EQ(strict.code(), ENOTSUP) << strict.error().message;
    EXPECT_NE(strict.error().message.find("exposure_us"), std::string::npos) << strict.error().message;
    strict = make_error(EIO, "closed");  // give the camera back before the next open

    config.controls.exposure.required = false;
    config.controls.gain.required = false;
    auto lenient = LibcameraCapture::open(config);
    ASSERT_TRUE(lenient.ok()) << lenient.error().message;
    const std::string text = (*lenient)->description();
    std::printf("default exposure 2000 us, gain 2: %s\n", text.c_str());
    EXPECT_NE(text.find("exposure_us"), std::string::npos) << text;
    EXPECT_NE(text.find("gain"), std::string::npos) << text;
    auto frame = (*lenient)->next_frame();
    ASSERT_TRUE(frame.ok()) << frame.error().message;
}

// Teardown gives everything back: the camera can be opened, streamed and closed again and again
// (a leaked acquire would be EBUSY, a leaked CameraManager slot EBUSY from this process).
// `mogao-camera info libcamera:` lists the camera, its Viewfinder formats and its controls, and
// refuses (EBUSY, not libcamera's abort) while a capture holds the process's CameraManager.
TEST(LibcameraCamera, DescribeListsFormatsAndControls) {
    LibcameraConfig config;
    config.width = 320;
    config.height = 240;
    {
        OPEN_LIBCAMERA_OR_SKIP(cam, config);
        auto busy = describe_libcamera_cameras("");
        ASSERT_FALSE(busy.ok());
        EXPECT_EQ(busy.code(), EBUSY) << busy.error().message;
    }
    auto text = describe_libcamera_cameras("");
    ASSERT_TRUE(text.ok()) << text.error().message;
    std::printf("%s", text->c_str());
    EXPECT_EQ(text->rfind("libcamera:", 0), 0U) << *text;
    EXPECT_NE(text->find("Viewfinder stream formats"), std::string::npos) << *text;
    EXPECT_NE(text->find("controls:"), std::string::npos) << *text;
    auto missing = describe_libcamera_cameras("/base/no/such/camera");
    ASSERT_FALSE(missing.ok());
    EXPECT_EQ(missing.code(), ENODEV);
    EXPECT_NE(missing.error().message.find("/base/no/such/camera"), std::string::npos) << missing.error().message;
}

TEST(LibcameraCamera, ReopensAfterCleanTeardown) {
    LibcameraConfig config;
    config.width = 320;
    config.height = 240;
    config.timeout_ms = 20000;
    for (int round = 0; round < 3; ++round) {
        OPEN_LIBCAMERA_OR_SKIP(cam, config);
        // The pipeline may adjust the size (vimc in libcamera 0.0.3: down to a multiple of 6).
        EXPECT_LE((*cam)->size().width, 320);
        EXPECT_GE((*cam)->size().width, 314);
        auto frame = (*cam)->next_frame();
        ASSERT_TRUE(frame.ok()) << "round " << round << ": " << frame.error().message;
        EXPECT_EQ(frame->image.width, (*cam)->size().width);
        EXPECT_EQ(frame->image.height, (*cam)->size().height);
    }
}

}  // namespace
}  // namespace mogao
