// SPDX-License-Identifier: Apache-2.0
#include "drivers/camera/camera_controls.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace mogao {
namespace {

TEST(CameraControls, DeviceValueRoundsToTheNearestStep) {
    // A UVC exposure: EXPOSURE_ABSOLUTE in 100 us units, [3, 2047], step 1.
    const ControlRange exposure{3, 2047, 1};
    auto v = to_device_value("exposure_us", 8000, exposure, 100.0, "us");
    ASSERT_TRUE(v.ok()) << v.error().message;
    EXPECT_EQ(*v, 80);
    v = to_device_value("exposure_us", 8049, exposure, 100.0, "us");
    ASSERT_TRUE(v.ok());
    EXPECT_EQ(*v, 80);
    // A gain with step 4 from 2: 2, 6, 10, ...
    const ControlRange gain{2, 42, 4};
    v = to_device_value("gain", 9, gain, 1.0, "");
    ASSERT_TRUE(v.ok());
    EXPECT_EQ(*v, 10);
    v = to_device_value("gain", 42, gain, 1.0, "");
    ASSERT_TRUE(v.ok());
    EXPECT_EQ(*v, 42);
}

TEST(CameraControls, OutOfRangeNamesTheKeyAndTheRangeInItsUnit) {
    const ControlRange exposure{3, 2047, 1};
    auto v = to_device_value("[navigation].camera_exposure_us", 300000, exposure, 100.0, "us");
    ASSERT_FALSE(v.ok());
    EXPECT_EQ(v.code(), EINVAL);
    EXPECT_NE(v.error().message.find("[navigation].camera_exposure_us = 300000 is outside the device's range [300, "
                                     "204700] us"),
              std::string::npos)
        << v.error().message;
    v = to_device_value("gain", -1, ControlRange{0, 255, 1}, 1.0, "");
    ASSERT_FALSE(v.ok());
    EXPECT_NE(v.error().message.find("[0, 255]"), std::string::npos) << v.error().message;
    v = to_device_value("gain", std::numeric_limits<double>::quiet_NaN(), ControlRange{0, 255, 1}, 1.0, "");
    ASSERT_FALSE(v.ok());
}

TEST(CameraControls, Describe) {
    ControlSetting s;
    EXPECT_EQ(describe(s), "keep");
    s.mode = ControlSetting::Mode::manual;
    s.value = 8000;
    EXPECT_EQ(describe(s), "manual 8000");
    s.mode = ControlSetting::Mode::lock;
    EXPECT_EQ(describe(s), "lock");
}

}  // namespace
}  // namespace mogao
