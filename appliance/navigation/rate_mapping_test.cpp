// SPDX-License-Identifier: Apache-2.0
#include "appliance/navigation/rate_mapping.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace mogao {
namespace {

const RateAxis kAxis{4.0, 30.0, 45.0, 1.0};

TEST(RateMapping, DeadZoneRampAndSaturation) {
    EXPECT_EQ(rate_from_offset(0.0, kAxis), 0.0);
    EXPECT_EQ(rate_from_offset(3.9, kAxis), 0.0);
    EXPECT_EQ(rate_from_offset(-4.0, kAxis), 0.0);
    EXPECT_NEAR(rate_from_offset(4.001, kAxis), 0.0, 0.01);   // continuous at the dead zone's edge
    EXPECT_NEAR(rate_from_offset(17.0, kAxis), 22.5, 1e-12);  // half way
    EXPECT_NEAR(rate_from_offset(-17.0, kAxis), -22.5, 1e-12);
    EXPECT_EQ(rate_from_offset(30.0, kAxis), 45.0);
    EXPECT_EQ(rate_from_offset(90.0, kAxis), 45.0);
    EXPECT_EQ(rate_from_offset(-90.0, kAxis), -45.0);
}

TEST(RateMapping, ExponentGivesFinerSlowControl) {
    RateAxis quadratic = kAxis;
    quadratic.exponent = 2.0;
    EXPECT_NEAR(rate_from_offset(17.0, quadratic), 45.0 * 0.25, 1e-12);
    EXPECT_EQ(rate_from_offset(30.0, quadratic), 45.0);
}

TEST(RateMapping, SlewLimitsTheStep) {
    EXPECT_EQ(slew_toward(0.0, 10.0, 2.0), 2.0);
    EXPECT_EQ(slew_toward(10.0, 0.0, 2.0), 8.0);
    EXPECT_EQ(slew_toward(1.0, 0.0, 2.0), 0.0);  // never overshoots
    EXPECT_EQ(slew_toward(5.0, 5.0, 0.0), 5.0);
}

TEST(RateMapping, ValidateNamesAxisAndLimit) {
    try {
        validate(RateAxis{5.0, 5.0, 1.0, 1.0}, "turn");
        FAIL() << "expected invalid_argument";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("turn.full_scale"), std::string::npos) << e.what();
    }
    EXPECT_THROW(validate(RateAxis{0.0, 1.0, -1.0, 1.0}, "x"), std::invalid_argument);
    EXPECT_THROW(validate(RateAxis{0.0, 1.0, 1.0, 0.5}, "x"), std::invalid_argument);
    EXPECT_NO_THROW(validate(kAxis, "turn"));
}

}  // namespace
}  // namespace mogao
