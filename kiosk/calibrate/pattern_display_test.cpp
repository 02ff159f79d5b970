// SPDX-License-Identifier: Apache-2.0
// The patterns reach the outputs exactly (every 8-bit code, sharp edges, per channel), camera codes
// become linear camera values, controls are locked, and the image budget adds up.
#include <gtest/gtest.h>

#include <cmath>

#include "appliance/autocal/rig_bridge.h"
#include "appliance/rig/rig_file.h"
#include "drivers/egl/egl_test_support.h"
#include "drivers/headless/headless_output.h"
#include "kiosk/calibrate/calibration_camera.h"
#include "kiosk/calibrate/pattern_budget.h"
#include "kiosk/calibrate/pattern_display.h"

namespace mogao::calibrate {
namespace {

std::unique_ptr<HeadlessOutputBackend> headless(std::vector<ImageSize> sizes) {
    auto b = HeadlessOutputBackend::create(HeadlessOptions{std::move(sizes), {}});
    if (!b) return nullptr;
    return std::move(b.value());
}

TEST(PatternDisplay, EveryCodeReachesTheOutputExactly) {
    auto backend = headless({{256, 3}, {64, 2}});
    if (!backend) return mogao::testing::skip_or_fail_without_egl("headless backend");
    auto display = PatternDisplay::create(*backend);
    ASSERT_TRUE(display) << display.error().message;
    // Output 0: grey codes 0..255 in row 0, their complement in row 1, a per-channel pattern in row 2.
    cv::Mat1f grey(3, 256);
    cv::Mat3f rgb(3, 256);
    for (int x = 0; x < 256; ++x) {
        grey(0, x) = static_cast<float>(x) / 255.0f;
        grey(1, x) = static_cast<float>(255 - x) / 255.0f;
        grey(2, x) = (x % 2) ? 1.0f : 0.0f;  // one-pixel stripes: no bleeding between neighbours
        for (int y = 0; y < 3; ++y)
            rgb(y, x) =
                cv::Vec3f(static_cast<float>(x), static_cast<float>((x * 7) % 256), static_cast<float>(255 - x)) /
                255.0f;
    }
    ASSERT_TRUE(display.value().show_outputs({grey, cv::Mat()}));
    const Rgb8Image& shown = backend->last_frame(0);
    for (int y = 0; y < 3; ++y) {
        for (int x = 0; x < 256; ++x) {
            const auto want = static_cast<int>(std::lround(255.0f * grey(y, x)));
            for (int c = 0; c < 3; ++c) {
                ASSERT_EQ(shown.pixels[static_cast<std::size_t>(3 * (y * 256 + x) + c)], want) << x << "," << y;
            }
        }
    }
    for (const std::uint8_t v : backend->last_frame(1).pixels) ASSERT_EQ(v, 0);  // no pattern: black
    ASSERT_TRUE(display.value().show_outputs({rgb, cv::Mat()}));
    for (int x = 0; x < 256; ++x) {
        const std::uint8_t* p = &backend->last_frame(0).pixels[static_cast<std::size_t>(3 * (256 + x))];
        EXPECT_EQ(p[0], x);
        EXPECT_EQ(p[1], (x * 7) % 256);
        EXPECT_EQ(p[2], 255 - x);
    }
    EXPECT_EQ(backend->frame_count(1), 1u);  // still black: not drawn again
    EXPECT_EQ(backend->frame_count(0), 2u);
    EXPECT_FALSE(display.value().show_outputs({cv::Mat1f(2, 2, 0.0f), cv::Mat()}));  // wrong size
    EXPECT_FALSE(display.value().show_outputs({cv::Mat()}));                         // wrong count
}

TEST(CalibrationCamera, CodesBecomeLinearCameraValues) {
    CameraFrame f;
    f.image = GrayImage(2, 1);
    f.image.pixels = {0, 255};
    EXPECT_FLOAT_EQ(camera_image(f, CameraTransfer::srgb)(0, 1), 1.0f);
    f.image.pixels = {51, 188};
    EXPECT_NEAR(camera_image(f, CameraTransfer::linear)(0, 0), 0.2f, 1e-6);
    EXPECT_NEAR(camera_image(f, CameraTransfer::srgb)(0, 1), 0.5029f, 1e-3);  // IEC 61966-2-1: 188 -> 0.503
    Rgb8Image colour;
    colour.size = {2, 1};
    colour.pixels = {255, 0, 0, 51, 51, 51};
    f.colour = colour;  // colour frames win over luma: mean of the decoded channels
    const cv::Mat1f img = camera_image(f, CameraTransfer::linear);
    EXPECT_NEAR(img(0, 0), 1.0f / 3.0f, 1e-6);
    EXPECT_NEAR(img(0, 1), 0.2f, 1e-6);
}

TEST(CalibrationCamera, ControlsAreLockedAndExposureRequired) {
    CameraControls asked;
    asked.gain = {ControlSetting::Mode::manual, 4.0, false, "gain"};
    asked.white_balance.mode = ControlSetting::Mode::automatic;
    const CameraControls c = locked_controls(asked);
    EXPECT_EQ(c.exposure.mode, ControlSetting::Mode::lock);
    EXPECT_TRUE(c.exposure.required);
    EXPECT_EQ(c.gain.mode, ControlSetting::Mode::manual);
    EXPECT_TRUE(c.gain.required);
    EXPECT_EQ(c.white_balance.mode, ControlSetting::Mode::lock);
    EXPECT_FALSE(c.white_balance.required);
    CameraSourceSpec spec;
    ASSERT_TRUE(parse_camera_source("v4l2:/dev/null", spec, nullptr));
    const auto camera = open_calibration_camera(spec);
    ASSERT_FALSE(camera);
    EXPECT_NE(camera.error().message.find("locked"), std::string::npos) << camera.error().message;
}

TEST(PatternBudget, StandardRigImageCount) {
    const auto prior = autocal::prior_from_rig(rig::load_rig(MOGAO_SOURCE_DIR "/rigs/standard.toml"));
    const PatternBudget b = pattern_budget(prior, true, {}, {});
    EXPECT_EQ(b.identification, 5);  // black, white, 3 alone
    // the camera timing's 4 single frames; black, white, 3 alone at white and at grey (the lit edges); per projector
    // 1920x1080: 11 + 11 Gray bits, each with its inverse, + white, black, + 8 phase shifts per axis
    EXPECT_EQ(b.geometry, 4 + 2 + 2 * 3 + 3 * (46 + 16));
    // black, 3 alone at white and at grey (the frame), black, 3 projectors' marks
    EXPECT_EQ(b.self_check, 2 * (2 + 3 * 3));
    EXPECT_EQ(b.colour, 5 + 3 + 3 * 3 * (8 + 4) + 8);  // black, black x4 long, each white long for the bounce
    // Motion-JPEG frames: 4 dithered exposures per image, 8 at the full level, 8 black frames long.
    EXPECT_EQ(pattern_budget(prior, true, {}, {}, {}, true).colour, 4 + 4 + 3 * 4 + 3 * 3 * (11 * 4 + 8) + 8);
    EXPECT_EQ(pattern_budget(prior, false, {}, {}).colour, 0);
    autocal::AutocalOptions fewer;
    fewer.max_gray_bits = 6;
    fewer.phase_shifts = 0;
    fewer.frames_per_pattern = 2;
    EXPECT_EQ(pattern_budget(prior, false, {}, fewer).geometry, 4 + 2 * (2 + 2 * 3 + 3 * (2 + 2 * (6 + 6))));
    EXPECT_NEAR(seconds_per_image(30.0, 150, 2), 0.25, 1e-12);
}

}  // namespace
}  // namespace mogao::calibrate
