// SPDX-License-Identifier: Apache-2.0
#include "kiosk/config/config_overrides.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "kiosk/config/kiosk_config_test_support.h"

namespace mogao {
namespace {

namespace fs = std::filesystem;
using kiosk_config_test::BadField;
using kiosk_config_test::KioskConfigTest;
using kiosk_config_test::read_source_file;
using kiosk_config_test::replace;

// --- the example with overrides (mogao-kiosk --print-config) -----------------------------------

TEST(ConfigOverrides, TheBuiltInExampleIsTheFileAndNoOverridesChangeNothing) {
    const std::string example = read_source_file("kiosk/config/kiosk.example.toml");
    EXPECT_EQ(kiosk_example_toml(), example) << "the built-in example is stale: re-run CMake";
    EXPECT_EQ(apply_config_overrides(example, {}), example);
}

TEST(ConfigOverrides, SetUncommentAndCommentOutKeysAndTables) {
    const std::string text = apply_config_overrides(
        kiosk_example_toml(), {"display.rate_hz=15", "outputs.png_every=3",
                               "stats.file=", "navigation.control.max_dt_s=0.5", "display.rate_hz=20"});
    EXPECT_NE(text.find("\nrate_hz = 20\n"), std::string::npos) << "the later override wins";
    EXPECT_EQ(text.find("rate_hz = 15"), std::string::npos);
    EXPECT_NE(text.find("\npng_every = 3\n"), std::string::npos);
    EXPECT_NE(text.find("\n# file = \"/var/lib/mogao/kiosk-stats.json\""), std::string::npos);
    EXPECT_NE(text.find("\n[navigation.control]"), std::string::npos);
    EXPECT_NE(text.find("\nmax_dt_s = 0.5\n"), std::string::npos);
    EXPECT_EQ(text.find("\n[navigation.detector]"), std::string::npos) << "an untouched table stays commented";
}

TEST(ConfigOverrides, RejectUnknownKeysSectionsMalformedOverridesAndInvalidToml) {
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"outputs.colour=1", "[outputs] has no field 'colour'"},
        {"display.png_every=1", "[display] has no field 'png_every'"},  // a key of another section
        {"displays.rate_hz=1", "no section [displays]"},
        {"rate_hz=30", "expected section.key=VALUE"},
        {"display.rate_hz", "expected section.key=VALUE"},
        {"farm.endpoint=[::1]:7443", "not valid TOML"},  // the quotes are the caller's
        {"display.rate_hz=1\nspp = 2", "one line"},
    };
    for (const auto& [override_text, expected] : cases) {
        try {
            (void)apply_config_overrides(kiosk_example_toml(), {override_text});
            ADD_FAILURE() << "accepted: " << override_text;
        } catch (const KioskConfigError& e) {
            EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(override_text), std::string::npos) << e.what();
        }
    }
}

TEST(ConfigOverrides, OverrideFilesSkipCommentsAndBlankLines) {
    const fs::path file = fs::temp_directory_path() / ("mogao-overrides-" + std::to_string(::getpid()));
    std::ofstream(file) << "# a comment\n\n  display.rate_hz=12\nstats.file=\n";
    const std::vector<std::string> got = expand_override_files({"quality.spp=2", "@" + file.string()});
    fs::remove(file);
    EXPECT_EQ(got, (std::vector<std::string>{"quality.spp=2", "display.rate_hz=12", "stats.file="}));
    EXPECT_THROW((void)expand_override_files({"@/nonexistent/overrides"}), KioskConfigError);
}

TEST(ParseSize, AcceptsOnlyWidthXHeight) {
    ImageSize s;
    EXPECT_TRUE(parse_size("1920x1080", s));
    EXPECT_EQ(s, (ImageSize{1920, 1080}));
    for (const char* bad : {"", "x", "1920", "1920x", "x1080", "-1x2", "1x-2", "1 x2", "1x2x3", "+1x2", "1234567x1"}) {
        EXPECT_FALSE(parse_size(bad, s)) << bad;
    }
}

}  // namespace
}  // namespace mogao
