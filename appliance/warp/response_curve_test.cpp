// SPDX-License-Identifier: Apache-2.0
#include "appliance/warp/response_curve.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

namespace mogao {
namespace {

TEST(ResponseCurve, GammaTableHoldsThePowerLawAtItsSamples) {
    const ResponseCurve r = make_gamma_response(2.2, 1025);
    for (const auto& lut : r.lut) {
        ASSERT_EQ(lut.size(), 1025U);
        EXPECT_EQ(lut.front(), 0.0F);
        EXPECT_EQ(lut.back(), 1.0F);
        EXPECT_FLOAT_EQ(lut[512], static_cast<float>(std::pow(0.5, 1.0 / 2.2)));
        EXPECT_FLOAT_EQ(lut[256], static_cast<float>(std::pow(0.25, 1.0 / 2.2)));
    }
    EXPECT_NO_THROW(validate_response(r));
}

TEST(ResponseCurve, ApplyInterpolatesAndClamps) {
    const ResponseCurve r = make_gamma_response(1.0, 2);  // identity
    EXPECT_FLOAT_EQ(apply_response(r, 0, 0.25F), 0.25F);
    EXPECT_FLOAT_EQ(apply_response(r, 2, 0.75F), 0.75F);
    EXPECT_EQ(apply_response(r, 1, -3.0F), 0.0F);
    EXPECT_EQ(apply_response(r, 1, 7.0F), 1.0F);
    EXPECT_EQ(apply_response(r, 1, NAN), 0.0F);
    // Between samples of a gamma table the error against the exact curve is small away from 0.
    const ResponseCurve g = make_gamma_response();
    EXPECT_NEAR(apply_response(g, 0, 0.5F), std::pow(0.5, 1.0 / 2.2), 1e-6);
    EXPECT_NEAR(apply_response(g, 0, 0.1F), std::pow(0.1, 1.0 / 2.2), 1e-5);
}

TEST(ResponseCurve, InverseUndoesApplyAcrossTheRange) {
    const ResponseCurve r = make_gamma_response();
    double worst = 0.0;
    for (int i = 0; i <= 10000; ++i) {
        const double x = i / 10000.0;
        const double back = invert_lut(r.lut[1], apply_lut(r.lut[1], x));
        worst = std::max(worst, std::abs(back - x));
    }
    EXPECT_LT(worst, 1e-6);
    EXPECT_EQ(invert_response(r, 0, -0.5F), 0.0F);
    EXPECT_EQ(invert_response(r, 0, 1.5F), 1.0F);
    EXPECT_EQ(invert_response(r, 0, NAN), 0.0F);
}

TEST(ResponseCurve, InverseOfAFlatRunIsItsLowestLinearValue) {
    ResponseCurve r;
    r.lut = {std::vector<float>{0.0F, 0.5F, 0.5F, 1.0F}, std::vector<float>{0.0F, 0.5F, 0.5F, 1.0F},
             std::vector<float>{0.2F, 0.2F, 0.2F, 0.2F}};
    ASSERT_NO_THROW(validate_response(r));
    EXPECT_NEAR(invert_response(r, 0, 0.5F), 1.0 / 3.0, 1e-7);
    EXPECT_NEAR(invert_response(r, 0, 0.75F), 2.5 / 3.0, 1e-7);
    EXPECT_EQ(invert_response(r, 2, 0.2F), 0.0F);
    EXPECT_EQ(invert_response(r, 2, 0.3F), 0.0F);  // above a flat table: its lowest linear value
}

std::string validation_message(const ResponseCurve& r) {
    try {
        validate_response(r, "proj0.response");
    } catch (const std::invalid_argument& e) {
        return e.what();
    }
    return "";
}

TEST(ResponseCurve, ValidationNamesTheChannelEntryAndLimit) {
    ResponseCurve r = make_gamma_response(2.2, 8);
    r.lut[1][3] = 0.01F;  // below entry 2
    EXPECT_NE(validation_message(r).find("proj0.response.lut[1][3]"), std::string::npos) << validation_message(r);
    EXPECT_NE(validation_message(r).find("non-decreasing"), std::string::npos);

    r = make_gamma_response(2.2, 8);
    r.lut[2][7] = 1.5F;
    EXPECT_NE(validation_message(r).find("outside [0, 1]"), std::string::npos);
    r.lut[2][7] = NAN;
    EXPECT_NE(validation_message(r).find("lut[2][7]"), std::string::npos);

    r = make_gamma_response(2.2, 8);
    r.lut[0] = {0.0F};
    EXPECT_NE(validation_message(r).find("outside [2,"), std::string::npos);

    r = make_gamma_response(2.2, 8);
    r.lut[2].push_back(1.0F);
    EXPECT_NE(validation_message(r).find("same length"), std::string::npos);
}

TEST(ResponseCurve, BadParametersThrow) {
    EXPECT_THROW((void)make_gamma_response(0.0), std::invalid_argument);
    EXPECT_THROW((void)make_gamma_response(NAN), std::invalid_argument);
    EXPECT_THROW((void)make_gamma_response(11.0), std::invalid_argument);
    EXPECT_THROW((void)make_gamma_response(2.2, 1), std::invalid_argument);
    EXPECT_THROW((void)make_gamma_response(2.2, kMaxResponseEntries + 1), std::invalid_argument);
}

}  // namespace
}  // namespace mogao
