// SPDX-License-Identifier: Apache-2.0
#include "appliance/autocal/indirect_light.h"

#include <cstdio>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "appliance/autocal/colour_calibration.h"
#include "appliance/autocal/colour_truth.h"
#include "appliance/autocal/rig_bridge.h"
#include "appliance/rig/rig_file.h"
#include "appliance/rig/virtual_rig.h"

namespace mogao::autocal {
namespace {

struct Calibrated {
    AutocalResult result;
    ColourResult colour;
};

Calibrated calibrate_rig(const rig::VirtualRig& truth) {
    RigPatternSource source(truth);
    const CalibrationPrior prior = prior_from_rig(truth);
    AutocalOptions o;
    o.warp_step_px = 4;
    Calibrated c{calibrate(source, prior, {960, 540}, o), {}};
    c.colour = calibrate_colour(source, prior.screen, c.result.camera, c.result.projectors, c.result.calibration);
    keep_screen_measurements(c.colour, c.result.screen);
    return c;
}

// A concave gain screen that throws back 80 % of its light: the colour step flattens each projector's direct light,
// and the screen's own light comes on top of it, brightest where the arc faces most of itself (a smooth field the
// calibration's maps cannot take out, because it depends on what is shown). Outputs that subtract the field the
// calibration predicts for the frame bring flat content back to about the same screen's flatness without
// interreflection, against the rig's ground truth (its own bounce model, written apart from the calibrator's).
TEST(IndirectLight, FlatContentOnAScreenThatLightsItselfComesOutFlat) {
    rig::VirtualRig rig = scaled_rig(rig::load_rig(std::string(MOGAO_SOURCE_DIR) + "/rigs/standard.toml"), 0.25, 0.25);
    rig.screen.gain = 1.3;
    rig.screen.half_gain_angle_deg = 40.0;
    const Calibrated matte_floor = calibrate_rig(rig);
    rig::VirtualRig lit = rig;
    lit.screen.interreflection = 0.8;
    const Calibrated c = calibrate_rig(lit);
    const IndirectLight indirect(c.result.screen, c.result.projectors, c.result.calibration);
    ASSERT_TRUE(indirect.active()) << c.result.screen.interreflection;
    for (const double level : {1.0, 0.5, 0.05}) {
        const SeamColour floor = measure_seam_colour(rig, matte_floor.result.calibration, level);
        const SeamColour left = measure_seam_colour(lit, c.result.calibration, level);
        const SeamColour taken = measure_seam_colour(lit, c.result.calibration, level, 0.01, &indirect);
        std::printf(
            "content %.2f: luminance deviation over the screen, p95: %.2f %% without interreflection, %.2f %% "
            "with it left on, %.2f %% taken out (seam p95 %.2f / %.2f / %.2f %%, seam max %.2f / %.2f / "
            "%.2f %%; reference %.4f / %.4f / %.4f)\n",
            level, 100.0 * floor.luminance_p95, 100.0 * left.luminance_p95, 100.0 * taken.luminance_p95,
            100.0 * floor.seam_luminance_p95, 100.0 * left.seam_luminance_p95, 100.0 * taken.seam_luminance_p95,
            100.0 * floor.seam_luminance_deviation, 100.0 * left.seam_luminance_deviation,
            100.0 * taken.seam_luminance_deviation, floor.reference_luminance, left.reference_luminance,
            taken.reference_luminance);
        // The screen's own light adds a smooth field over the whole screen: at least two thirds of what it adds to
        // the deviations' p95 is taken off.
        ASSERT_GT(left.luminance_p95, floor.luminance_p95 + 0.002) << "the rig's interreflection shows too little";
        EXPECT_LT(taken.luminance_p95 - floor.luminance_p95, (left.luminance_p95 - floor.luminance_p95) / 3.0) << level;
    }
}

TEST(IndirectLight, RefusesWhatItCannotModelNamingTheField) {
    ScreenModel screen;
    screen.interreflection = 1.0;
    try {
        (void)IndirectLight(screen, {}, {});
        ADD_FAILURE() << "a reflectance of 1 accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("interreflection"), std::string::npos) << e.what();
    }
    screen.interreflection = 0.5;
    ScreenCalibration one;
    one.projectors.resize(1);
    try {
        (void)IndirectLight(screen, {}, one);
        ADD_FAILURE() << "0 models for 1 projector accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("projector models"), std::string::npos) << e.what();
    }
    const IndirectLight some(screen, {}, {});
    EXPECT_TRUE(some.active());
    EXPECT_THROW((void)some.field(RgbFloatImage(ImageSize{some.columns() + 1, some.rows()})), std::invalid_argument);
    screen.interreflection = 0.005;  // a matte screen's measured reflectance: nothing to take out
    const IndirectLight matte(screen, {}, {});
    EXPECT_FALSE(matte.active());
    EXPECT_TRUE(matte.flat_field(1.0).pixels.empty());
}

}  // namespace
}  // namespace mogao::autocal
