// SPDX-License-Identifier: Apache-2.0
#include "appliance/warp/calibration_validation.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "appliance/warp/ideal_calibration.h"

namespace mogao {
namespace {

ScreenCalibration small_screen() {
    IdealCalibrationParams p;
    p.projectors = 2;
    p.output = {8, 6};
    p.content = {16, 6};
    p.response_entries = 16;
    return make_ideal_calibration(p);
}

std::string message_of(const ScreenCalibration& s) {
    try {
        validate_screen(s);
    } catch (const std::invalid_argument& e) {
        return e.what();
    }
    return "";
}

TEST(CalibrationValidation, IdealCalibrationIsValid) { EXPECT_EQ(message_of(small_screen()), ""); }

TEST(CalibrationValidation, WarpValuesMustBeFiniteOrNanPairs) {
    ScreenCalibration s = small_screen();
    s.projectors[1].warp.uv[2 * 9] = NAN;  // u NaN, v finite
    EXPECT_NE(message_of(s).find("projectors[1] 'proj1'.warp: sample (1, 1)"), std::string::npos) << message_of(s);
    s.projectors[1].warp.uv[2 * 9 + 1] = NAN;  // now both NaN: "no content"
    EXPECT_EQ(message_of(s), "");
    s.projectors[0].warp.uv[0] = INFINITY;
    EXPECT_NE(message_of(s).find("must be finite or NaN in both"), std::string::npos);
    s = small_screen();
    s.projectors[0].warp.uv[3] = 1.7F;  // outside [0, 1] is allowed (aims past the content edge)
    EXPECT_EQ(message_of(s), "");
}

TEST(CalibrationValidation, SizesMustBeConsistent) {
    ScreenCalibration s = small_screen();
    s.projectors[0].warp.uv.pop_back();
    EXPECT_NE(message_of(s).find("uv holds 95 values, 8x6 x 2 = 96 expected"), std::string::npos) << message_of(s);
    s = small_screen();
    s.projectors[0].blend.size = {9, 6};
    s.projectors[0].blend.weight.resize(54, 1.0F);
    EXPECT_NE(message_of(s).find("finer than the output"), std::string::npos) << message_of(s);
    s = small_screen();
    s.content = {0, 6};
    EXPECT_NE(message_of(s).find("screen.content: size 0x6 is outside 1..16384"), std::string::npos);
    s = small_screen();
    s.projectors[0].output = {16385, 6};
    EXPECT_NE(message_of(s).find("outside 1..16384"), std::string::npos);
}

TEST(CalibrationValidation, WeightsMustBeInUnitRange) {
    ScreenCalibration s = small_screen();
    s.projectors[1].blend.weight[5] = 1.2F;
    EXPECT_NE(message_of(s).find("blend: weight (5, 0) = 1.2"), std::string::npos) << message_of(s);
    s.projectors[1].blend.weight[5] = NAN;
    EXPECT_NE(message_of(s).find("outside [0, 1]"), std::string::npos);
    s.projectors[1].blend.weight[5] = -0.0F;
    EXPECT_EQ(message_of(s), "");
}

TEST(CalibrationValidation, ScreenLevelRules) {
    ScreenCalibration s = small_screen();
    s.projectors[1].id = "proj0";
    EXPECT_NE(message_of(s).find("id is used by an earlier projector"), std::string::npos);
    s.projectors[1].id = "";
    EXPECT_NE(message_of(s).find("id is empty"), std::string::npos);
    s.projectors.clear();
    EXPECT_NE(message_of(s).find("0 projectors, outside 1..64"), std::string::npos);
    s = small_screen();
    s.projectors[0].response.lut[0][3] = 0.0F;
    EXPECT_NE(message_of(s).find("response.lut[0][3]"), std::string::npos) << message_of(s);
}

}  // namespace
}  // namespace mogao
