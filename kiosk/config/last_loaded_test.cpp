// SPDX-License-Identifier: Apache-2.0
// A bad configuration or calibration at start-up keeps the last good one (kiosk/config/last_loaded.h,
// kiosk_setup.h) instead of exiting, and says so: real files, the real parsers and MPCDI reader/writer.
#include "kiosk/config/last_loaded.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <string>

#include "appliance/calibration/mpcdi_screen.h"
#include "appliance/calibration/mpcdi_writer.h"
#include "appliance/warp/ideal_calibration.h"
#include "kiosk/config/config_overrides.h"
#include "kiosk/loop/kiosk_setup.h"
#include "kiosk/stats/kiosk_status.h"

namespace mogao {
namespace {

namespace fs = std::filesystem;

class LastLoadedTest : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("mogao-last-loaded-" + std::to_string(::getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_ / "pki");
        for (const char* f : {"pki/ca.pem", "pki/a.pem", "pki/a.key"}) std::ofstream(dir_ / f) << "x";
    }
    void TearDown() override { fs::remove_all(dir_); }

    void write_config(const std::vector<std::string>& more) {
        std::vector<std::string> all = {R"(farm.endpoint="[::1]:7443")", R"(farm.ca="pki/ca.pem")",
                                        R"(farm.cert="pki/a.pem")",      R"(farm.key="pki/a.key")",
                                        R"(outputs.backend="headless")", R"(quality.content="320x180")"};
        all.insert(all.end(), more.begin(), more.end());
        std::ofstream(dir_ / "kiosk.toml") << apply_config_overrides(kiosk_example_toml(), all);
    }

    fs::path dir_;
};

// On the appliance /etc/mogao is read-only: the unit names a writable folder for the copies.
TEST_F(LastLoadedTest, CopiesGoToMogaoLastGoodDirWhenTheEnvironmentNamesOne) {
    std::ofstream(dir_ / "cal.mpcdi") << "bytes";
    EXPECT_EQ(last_loaded_path(dir_ / "cal.mpcdi"), dir_ / "cal.mpcdi.last-loaded");
    const fs::path state = dir_ / "state" / "last-good";
    ASSERT_EQ(::setenv("MOGAO_LAST_GOOD_DIR", state.c_str(), 1), 0);
    const fs::path copy = last_loaded_path(dir_ / "cal.mpcdi");
    keep_last_loaded(dir_ / "cal.mpcdi");
    ::unsetenv("MOGAO_LAST_GOOD_DIR");
    EXPECT_EQ(copy.parent_path(), state);
    EXPECT_NE(copy.filename().string().find("cal.mpcdi.last-loaded"), std::string::npos) << copy;
    std::ifstream in(copy);
    std::string bytes;
    in >> bytes;
    EXPECT_EQ(bytes, "bytes") << "no copy at " << copy;
    EXPECT_FALSE(fs::exists(dir_ / "cal.mpcdi.last-loaded"));
}

TEST_F(LastLoadedTest, ABadConfigurationRunsOnItsLastGoodCopy) {
    write_config({R"(calibration.source="ideal")", "quality.spp=3"});
    const KioskSetup good = load_setup(dir_ / "kiosk.toml", "", "", true);
    EXPECT_TRUE(good.fallbacks.empty());
    ASSERT_TRUE(fs::exists(dir_ / "kiosk.toml.last-loaded")) << "the good file is kept";
    write_config({R"(calibration.source="ideal")", "quality.spp=0"});  // bad: outside [1, 4096]
    const KioskSetup fallen = load_setup(dir_ / "kiosk.toml", "", "", true);
    EXPECT_EQ(fallen.config.quality.spp, 3) << "the last good configuration runs";
    ASSERT_EQ(fallen.fallbacks.size(), 1u);
    EXPECT_EQ(fallen.fallbacks[0].wall, "CONFIG ERROR - LAST GOOD IN USE");
    EXPECT_NE(fallen.fallbacks[0].message.find("[quality].spp = 0 is outside [1, 4096]"), std::string::npos)
        << fallen.fallbacks[0].message;
    EXPECT_NE(fallen.fallbacks[0].message.find("kiosk.toml.last-loaded"), std::string::npos);
    // The bad file did not replace the good copy; --check-config (no fall back) still fails on it.
    EXPECT_EQ(load_kiosk_config(dir_ / "kiosk.toml.last-loaded").quality.spp, 3);
    try {
        (void)load_setup(dir_ / "kiosk.toml", "", "", false);
        FAIL() << "the bad file was accepted without falling back";
    } catch (const KioskSetupError& e) {
        EXPECT_EQ(e.exit_code, 2);
    }
    fs::remove(dir_ / "kiosk.toml.last-loaded");  // no copy: the kiosk exits as before
    EXPECT_THROW((void)load_setup(dir_ / "kiosk.toml", "", "", true), KioskSetupError);
}

TEST_F(LastLoadedTest, ABadCalibrationRunsOnItsLastGoodCopyAndTheStatusFileSaysSo) {
    IdealCalibrationParams ideal;
    ideal.projectors = 2;
    ideal.output = {64, 48};
    ideal.content = {320, 180};
    write_mpcdi(dir_ / "screen.mpcdi", to_mpcdi(make_ideal_calibration(ideal)));
    write_config({R"(calibration.source="screen.mpcdi")",
                  "calibration.projectors=", "calibration.overlap=", "calibration.output=", "calibration.gamma="});
    const KioskConfig config = load_kiosk_config(dir_ / "kiosk.toml");
    std::vector<StartFallback> fallbacks;
    EXPECT_EQ(load_calibration(config, &fallbacks).projectors.size(), 2u);
    EXPECT_TRUE(fallbacks.empty());
    ASSERT_TRUE(fs::exists(dir_ / "screen.mpcdi.last-loaded"));
    std::ofstream(dir_ / "screen.mpcdi", std::ios::trunc) << "PK not a zip";  // a corrupt calibration
    const ScreenCalibration fallen = load_calibration(config, &fallbacks);
    EXPECT_EQ(fallen.projectors.size(), 2u);
    ASSERT_EQ(fallbacks.size(), 1u);
    EXPECT_EQ(fallbacks[0].wall, "CALIBRATION ERROR - LAST GOOD IN USE");
    EXPECT_NE(fallbacks[0].message.find("screen.mpcdi"), std::string::npos) << fallbacks[0].message;
    try {
        (void)load_calibration(config);  // without fall back: exits as before
        FAIL();
    } catch (const KioskSetupError& e) {
        EXPECT_EQ(e.exit_code, 1);
    }
    KioskStatus status;
    for (const auto& f : fallbacks) status.fallbacks.push_back(f.message);
    EXPECT_EQ(kiosk_status_json(status)["fallbacks"][0], fallbacks[0].message);
}

}  // namespace
}  // namespace mogao
