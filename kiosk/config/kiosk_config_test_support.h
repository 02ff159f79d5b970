// SPDX-License-Identifier: Apache-2.0
// The kiosk configuration tests' shared parts: a folder with the files a configuration references,
// and the shipped example with every field set (kiosk_config_test.cpp, kiosk_config_tracking_test.cpp).
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "appliance/tracker/camera_intrinsics.h"
#include "kiosk/config/config_overrides.h"
#include "kiosk/config/kiosk_config.h"

namespace mogao::kiosk_config_test {

namespace fs = std::filesystem;

// A folder with the files a configuration references (contents do not matter to the parser).
class KioskConfigTest : public ::testing::Test {
public:  // the free helpers below build on good()
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("mogao-kiosk-config-" + std::to_string(::getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_ / "pki");
        for (const char* f :
             {"pki/ca.pem", "pki/appliance-a.pem", "pki/appliance-a.key", "screen.mpcdi", "tour.json"}) {
            std::ofstream(dir_ / f) << "x";
        }
        // A replay folder with its camera.json (as `mogao-tag-sequence` writes it), and a
        // separate calibration file.
        fs::create_directories(dir_ / "seq");
        CameraIntrinsics camera;
        camera.width = 800;
        camera.height = 600;
        camera.fx = camera.fy = 700.0;
        camera.cx = 399.5;
        camera.cy = 299.5;
        write_intrinsics(dir_ / "seq/camera.json", camera);
        write_intrinsics(dir_ / "webcam.json", camera);
        std::ofstream(dir_ / "broken.json") << "{\"image_width\": 800}";
    }
    void TearDown() override { fs::remove_all(dir_); }

    [[nodiscard]] fs::path name() const { return dir_ / "kiosk.toml"; }

    // Every field set, valid: kiosk.example.toml with kGood's overrides (defined below).
    static std::string good(const std::vector<std::string>& more = {});

    [[nodiscard]] KioskConfig parse(const std::string& text) const { return parse_kiosk_config(text, name()); }

    // The message of the KioskConfigError that parsing `text` throws ("" if it does not throw).
    [[nodiscard]] std::string error_of(const std::string& text) const {
        try {
            (void)parse(text);
        } catch (const KioskConfigError& e) {
            return e.what();
        }
        return "";
    }

    fs::path dir_;
};

inline std::string read_source_file(const char* relative) {
    std::ifstream in(fs::path(MOGAO_SOURCE_DIR) / relative);
    EXPECT_TRUE(in) << relative << " not found";
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Overrides of the shipped example that set every field (the files are made by SetUp).
inline const std::vector<std::string> kGood = {R"(farm.endpoint="[fd00:6d6f::1]:7443")",
                                               R"(farm.server_name="farm-1")",
                                               R"(farm.ca="pki/ca.pem")",
                                               R"(farm.cert="pki/appliance-a.pem")",
                                               R"(farm.key="pki/appliance-a.key")",
                                               "display.rate_hz=25",
                                               "display.flip_timeout_s=12",
                                               R"(outputs.backend="headless")",
                                               R"(outputs.sizes=["320x240", "320x240", "320x240"])",
                                               R"(outputs.png_dir="out/png")",
                                               "outputs.png_every=5",
                                               "outputs.composite=true",
                                               R"(calibration.source="ideal")",
                                               "calibration.projectors=3",
                                               "calibration.overlap=0.2",
                                               R"(calibration.output="320x240")",
                                               "calibration.gamma=2.4",
                                               R"(quality.content="480x270")",
                                               "quality.spp=2",
                                               "quality.jpeg_quality=90",
                                               "quality.bounces=1",
                                               "quality.ao_samples=4",
                                               "quality.area_light_samples=2",
                                               "screen.radius_m=3.5",
                                               "screen.arc_deg=160",
                                               "screen.bottom_m=0.1",
                                               "screen.top_m=2.9",
                                               "screen.guard_deg=5",
                                               R"(navigation.path="orbit")",
                                               "navigation.path_frames=120",
                                               "navigation.start=[0.0, 0.0, 4.0]",
                                               "navigation.start_yaw_deg=10",
                                               "navigation.eye_height_m=1.5",
                                               R"(stats.file="out/stats.json")",
                                               "stats.log_period_s=2.5"};

inline std::string KioskConfigTest::good(const std::vector<std::string>& more) {
    std::vector<std::string> overrides = kGood;
    overrides.insert(overrides.end(), more.begin(), more.end());
    return apply_config_overrides(read_source_file("kiosk/config/kiosk.example.toml"), overrides);
}

// `text` with the first occurrence of `from` replaced by `to` (fails the test if absent).
inline std::string replace(std::string text, const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << "test bug: '" << from << "' is not in the configuration";
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return text;
}

struct BadField {
    const char* from;
    const char* to;
    const char* expected;  // substring of the message, after "<file>:<line>: "
};

}  // namespace mogao::kiosk_config_test
