// SPDX-License-Identifier: Apache-2.0
// The models file (model_store.h): round trip of the standard rig's exact models, and every kind of
// bad input refused with the file and the field named.
#include "appliance/autocal/model_store.h"

#include <unistd.h>

#include <cmath>
#include <fstream>
#include <limits>

#include <gtest/gtest.h>

#include "appliance/autocal/rig_bridge.h"
#include "appliance/rig/rig_file.h"

namespace mogao::autocal {
namespace {

namespace fs = std::filesystem;

class ModelStoreTest : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("mogao-model-store-" + std::to_string(::getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_);
        const rig::VirtualRig rig =
            scaled_rig(rig::load_rig(std::string(MOGAO_SOURCE_DIR) + "/rigs/standard.toml"), 0.25, 0.25);
        const CalibrationPrior prior = prior_from_rig(rig);
        models_.screen = prior.screen;
        models_.camera = prior.camera;
        // The rig's TRUE projector poses (the prior's are not used), as a fitted result would be.
        for (std::size_t k = 0; k < rig.projectors.size(); ++k) {
            DeviceModel d = prior.projectors[k];
            d.rotation = rig::device_to_screen(rig.projectors[k].pose);
            d.position_m = rig.projectors[k].pose.position_m;
            if (k == 1) d.falloff = {{1.02, 0.01, -0.02, -0.2, 0.03, -0.25}};  // a measured lens fall-off
            models_.projectors.push_back(d);
        }
    }
    void TearDown() override { fs::remove_all(dir_); }

    // The models' JSON with `edit` applied, written and read back: the error message.
    std::string error_of(const std::function<void(nlohmann::json&)>& edit) {
        nlohmann::json j = models_json(models_);
        edit(j);
        const fs::path file = dir_ / "bad.models.json";
        std::ofstream(file) << j.dump();
        try {
            (void)read_models(file);
        } catch (const ModelStoreError& e) {
            return e.what();
        }
        return "(accepted)";
    }

    fs::path dir_;
    CalibrationModels models_;
};

TEST_F(ModelStoreTest, RoundTripKeepsEveryField) {
    const fs::path file = models_path_for(dir_ / "calibration.mpcdi");
    EXPECT_EQ(file.filename(), "calibration.models.json");
    models_.screen.bow_m = {0.03, -0.001, 0.0005, 0.0};  // a bowed screen's modes survive the file
    write_models(file, models_);
    const CalibrationModels back = read_models(file);
    EXPECT_EQ(back.screen.bow_m, models_.screen.bow_m);
    EXPECT_EQ(back.screen.radius_m, models_.screen.radius_m);
    EXPECT_EQ(back.screen.arc_deg, models_.screen.arc_deg);
    EXPECT_EQ(back.screen.top_m, models_.screen.top_m);
    ASSERT_EQ(back.projectors.size(), models_.projectors.size());
    const auto same = [](const DeviceModel& a, const DeviceModel& b) {
        EXPECT_EQ(a.id, b.id);
        EXPECT_EQ(a.resolution.width, b.resolution.width);
        EXPECT_EQ(a.resolution.height, b.resolution.height);
        EXPECT_EQ(a.fx_px, b.fx_px);  // nlohmann writes doubles to round-trip exactly
        EXPECT_EQ(a.fy_px, b.fy_px);
        EXPECT_EQ(a.cx_px, b.cx_px);
        EXPECT_EQ(a.cy_px, b.cy_px);
        EXPECT_EQ(a.distortion, b.distortion);
        EXPECT_EQ(a.rotation, b.rotation);
        EXPECT_EQ(a.position_m, b.position_m);
        EXPECT_EQ(a.falloff.c, b.falloff.c);
    };
    same(back.camera, models_.camera);
    for (std::size_t k = 0; k < back.projectors.size(); ++k) same(back.projectors[k], models_.projectors[k]);
    EXPECT_FALSE(back.projectors[1].falloff.flat());
    // A flat projector writes no "falloff" (files from before it read the same); absent reads flat.
    EXPECT_FALSE(models_json(models_)["projectors"][0].contains("falloff"));
    EXPECT_FALSE(fs::exists(file.string() + ".tmp")) << "no temporary left behind";
    // A projector's fitted lens distortion is written and read back (self-recalibration models it).
    models_.projectors[2].distortion = {-0.04, 0.01, 0.001, -0.002, 0.0};
    write_models(file, models_);
    EXPECT_EQ(read_models(file).projectors[2].distortion, models_.projectors[2].distortion);
}

TEST_F(ModelStoreTest, MatchesTheCalibrationBuiltFromIt) {
    const ScreenCalibration c = calibration_from_models(models_.projectors, models_.screen, {480, 270}, {8});
    EXPECT_NO_THROW(check_models_match(models_, c, "m.json"));
    ScreenCalibration fewer = c;
    fewer.projectors.pop_back();
    try {
        check_models_match(models_, fewer, "m.json");
        FAIL() << "3 models accepted for 2 projectors";
    } catch (const ModelStoreError& e) {
        EXPECT_STREQ(e.what(), "m.json: projectors has 3 entries, the calibration has 2 projectors");
    }
    ScreenCalibration renamed = c;
    renamed.projectors[1].id = "left";
    EXPECT_THROW(check_models_match(models_, renamed, "m.json"), ModelStoreError);
    ScreenCalibration resized = c;
    resized.projectors[2].output.width += 1;
    try {
        check_models_match(models_, resized, "m.json");
        FAIL();
    } catch (const ModelStoreError& e) {
        EXPECT_NE(std::string(e.what()).find("projectors[2].resolution"), std::string::npos) << e.what();
    }
}

TEST_F(ModelStoreTest, BadInputNamesFileFieldAndLimit) {
    const std::string file = (dir_ / "bad.models.json").string();
    EXPECT_EQ(error_of([](nlohmann::json& j) { j["projectors"].erase(1); }), "(accepted)")
        << "two projectors are a valid file; the count is checked against the MPCDI";
    EXPECT_EQ(error_of([](nlohmann::json& j) { j["projectors"][1].erase("fx_px"); }),
              file + ": projectors[1].fx_px is missing");
    EXPECT_EQ(error_of([](nlohmann::json& j) { j["projectors"][0]["fy_px"] = -3.0; }),
              file + ": projectors[0].fy_px = -3 is outside (0, 1e6] px");
    EXPECT_EQ(error_of([](nlohmann::json& j) { j["camera"]["position_m"][2] = nullptr; }),
              file + ": camera.position_m[2] must be a number, got null");
    EXPECT_EQ(error_of([](nlohmann::json& j) { j["projectors"] = nlohmann::json::array(); }),
              file + ": projectors must be an array of 1 to 64 projectors");
    EXPECT_EQ(error_of([](nlohmann::json& j) { j.erase("projectors"); }), file + ": projectors is missing");
    EXPECT_EQ(error_of([](nlohmann::json& j) { j["screen"]["bow_m"][1] = 0.5; }),
              file + ": screen.bow_m[1] = 0.5 is outside [-0.1, 0.1] x radius_m");
    EXPECT_EQ(error_of([](nlohmann::json& j) { j["screen"].erase("bow_m"); }), "(accepted)")
        << "files from before the bow: a cylinder";
    EXPECT_EQ(error_of([](nlohmann::json& j) { j["version"] = 2; }),
              file + ": version = 2 is not 1 (the one this reader knows)");
    EXPECT_NE(error_of([](nlohmann::json& j) {
                  j["screen"]["top_m"] = -0.5;
              }).find(file + ": screen.top_m = -0.5 must be above bottom_m = "),
              std::string::npos);
    EXPECT_NE(error_of([](nlohmann::json& j) {
                  j["projectors"][2]["rotation"][0][0] = 0.5;
              }).find(file + ": projectors[2].rotation is not orthonormal"),
              std::string::npos);
    EXPECT_EQ(error_of([](nlohmann::json& j) { j["camera"]["falloff"] = {1, 0, 0, 0, 0, 0}; }),
              file + ": camera.falloff is a projector's (the camera has none)");
    EXPECT_EQ(error_of([](nlohmann::json& j) { j["projectors"][1]["falloff"][5] = 11.0; }),
              file + ": projectors[1].falloff[5] = 11 is outside [-10, 10]");
    EXPECT_NE(error_of([](nlohmann::json& j) {
                  j["projectors"][1]["falloff"][3] = -3.0;
              }).find(file + ": projectors[1].falloff gives "),
              std::string::npos);
    // A projector's lens distortion: within a projection lens's coefficients, and one ray per image position.
    EXPECT_EQ(error_of([](nlohmann::json& j) { j["projectors"][0]["distortion"][2] = 0.5; }),
              file + ": projectors[0].distortion[2] = 0.5 is outside [-0.1, 0.1] (a projection lens's)");
    EXPECT_NE(error_of([](nlohmann::json& j) {
                  j["projectors"][0]["distortion"] = {-0.9, 0.0, 0.0, 0.0, 0.0};
              }).find(file + ": projectors[0].distortion is not one-to-one out to 1.2 times the image's corners"),
              std::string::npos);
    EXPECT_EQ(error_of([](nlohmann::json& j) {
                  j["camera"]["resolution"] = {640.5, 480};
              }),
              file + ": camera.resolution must be whole pixels");
    // Not JSON at all, and a missing file.
    std::ofstream(file) << "{\"format\": ";
    EXPECT_THROW(
        {
            try {
                (void)read_models(file);
            } catch (const ModelStoreError& e) {
                EXPECT_EQ(std::string(e.what()), file + ": not valid JSON");
                throw;
            }
        },
        ModelStoreError);
    EXPECT_THROW((void)read_models(dir_ / "absent.json"), ModelStoreError);
}

TEST_F(ModelStoreTest, NonFiniteModelsAreNeverWrittenAndTheOldFileStays) {
    const fs::path file = dir_ / "calibration.models.json";
    write_models(file, models_);
    CalibrationModels bad = models_;
    bad.projectors[1].cx_px = std::numeric_limits<double>::quiet_NaN();
    try {
        write_models(file, bad);
        FAIL() << "a NaN principal point was written";
    } catch (const ModelStoreError& e) {
        EXPECT_NE(std::string(e.what()).find("projectors[1].cx_px = nan is outside [-1e6, 1e6] px"), std::string::npos)
            << e.what();
    }
    EXPECT_EQ(read_models(file).projectors[1].cx_px, models_.projectors[1].cx_px);
}

}  // namespace
}  // namespace mogao::autocal
