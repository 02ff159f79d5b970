// SPDX-License-Identifier: Apache-2.0
#include "kiosk/config/kiosk_config.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include "common/quality_preset.h"
#include "common/toml_nesting.h"
#include "kiosk/config/config_overrides.h"
#include "kiosk/config/kiosk_config_test_support.h"

namespace mogao {
namespace {

namespace fs = std::filesystem;
using kiosk_config_test::BadField;
using kiosk_config_test::KioskConfigTest;
using kiosk_config_test::read_source_file;
using kiosk_config_test::replace;

TEST_F(KioskConfigTest, ReadsEveryFieldAndResolvesPathsAgainstTheFile) {
    const KioskConfig c = parse(good());
    EXPECT_EQ(c.farm.endpoint, "[fd00:6d6f::1]:7443");
    EXPECT_EQ(c.farm.server_name, "farm-1");
    EXPECT_EQ(c.farm.ca, dir_ / "pki/ca.pem");
    EXPECT_EQ(c.farm.key, dir_ / "pki/appliance-a.key");
    EXPECT_DOUBLE_EQ(c.outputs.rate_hz, 25.0);
    EXPECT_DOUBLE_EQ(c.outputs.flip_timeout_s, 12.0);
    EXPECT_EQ(c.outputs.backend, OutputKind::headless);
    ASSERT_EQ(c.outputs.sizes.size(), 3u);
    EXPECT_EQ(c.outputs.sizes[2], (ImageSize{320, 240}));
    EXPECT_EQ(c.outputs.png_dir, dir_ / "out/png");
    EXPECT_EQ(c.outputs.png_every, 5);
    EXPECT_TRUE(c.calibration.mpcdi.empty());
    EXPECT_EQ(c.calibration.projectors, 3);
    EXPECT_DOUBLE_EQ(c.calibration.overlap, 0.2);
    EXPECT_EQ(c.calibration.output, (ImageSize{320, 240}));
    EXPECT_DOUBLE_EQ(c.calibration.gamma, 2.4);
    EXPECT_EQ(c.quality.content, (ImageSize{480, 270}));
    EXPECT_EQ(c.quality.spp, 2);
    EXPECT_EQ(c.quality.jpeg_quality, 90);
    EXPECT_EQ(c.quality.max_bounces, 1);
    EXPECT_EQ(c.quality.ao_samples, 4);
    EXPECT_EQ(c.quality.area_light_samples, 2);
    EXPECT_DOUBLE_EQ(c.screen.radius_m, 3.5);
    EXPECT_DOUBLE_EQ(c.screen.arc_deg, 160.0);
    EXPECT_DOUBLE_EQ(c.screen.bottom_m, 0.1);
    EXPECT_DOUBLE_EQ(c.screen.top_m, 2.9);
    EXPECT_DOUBLE_EQ(c.guard_deg, 5.0);
    EXPECT_DOUBLE_EQ(c.screen.eye_m.y(), 1.5);  // the camera's eye is the visitor's eye height
    EXPECT_EQ(c.navigation.path, "orbit");
    EXPECT_EQ(c.navigation.path_frames, 120);
    EXPECT_DOUBLE_EQ(c.navigation.start.z(), 4.0);
    EXPECT_DOUBLE_EQ(c.navigation.start_yaw_deg, 10.0);
    EXPECT_EQ(c.stats.file, dir_ / "out/stats.json");
    EXPECT_DOUBLE_EQ(c.stats.log_period_s, 2.5);
}

TEST_F(KioskConfigTest, OnlyTheFarmIsRequired) {
    const KioskConfig c = parse(R"([farm]
endpoint = "[::1]:7443"
ca = "pki/ca.pem"
cert = "pki/appliance-a.pem"
key = "pki/appliance-a.key"
)");
    EXPECT_EQ(c.outputs.backend, OutputKind::kms);
    EXPECT_TRUE(c.outputs.device.empty());
    EXPECT_EQ(c.navigation.path, "walk");
    EXPECT_EQ(c.quality.content, (ImageSize{1920, 1080}));
    EXPECT_TRUE(c.stats.file.empty());
}

// [quality].preset takes the farm's preset table (common/quality_preset.h); a key written in the
// file overrides its preset's value; an unknown name is an error naming the known ones.
TEST_F(KioskConfigTest, QualityPresetSetsTheRequestAndExplicitKeysOverrideIt) {
    const std::string farm = R"([farm]
endpoint = "[::1]:7443"
ca = "pki/ca.pem"
cert = "pki/appliance-a.pem"
key = "pki/appliance-a.key"
)";
    const KioskConfig exhibit = parse(farm + "[quality]\npreset = \"exhibit\"\n");
    const QualityPreset* table = quality_preset("exhibit");
    ASSERT_NE(table, nullptr);
    EXPECT_EQ(exhibit.quality.preset, "exhibit");
    EXPECT_EQ(exhibit.quality.spp, table->request.spp);
    EXPECT_EQ(exhibit.quality.max_bounces, table->request.max_bounces);
    EXPECT_EQ(exhibit.quality.jpeg_quality, table->request.jpeg_quality);
    EXPECT_EQ(exhibit.quality.ao_samples, table->request.ao_samples);
    EXPECT_EQ(exhibit.quality.area_light_samples, table->request.area_light_samples);
    EXPECT_NE(exhibit.quality.spp, QualityConfig{}.spp) << "the preset must change something";

    const KioskConfig overridden = parse(farm + "[quality]\npreset = \"exhibit\"\nspp = 3\n");
    EXPECT_EQ(overridden.quality.spp, 3);
    EXPECT_EQ(overridden.quality.max_bounces, table->request.max_bounces);

    const std::string message = error_of(farm + "[quality]\npreset = \"cinema\"\n");
    EXPECT_NE(message.find("[quality].preset"), std::string::npos) << message;
    EXPECT_NE(message.find("'cinema' is not one of interactive, balanced, exhibit"), std::string::npos) << message;
}

TEST_F(KioskConfigTest, AcceptsAnMpcdiSourceAPathFileAndKmsDevice) {
    // Empty values comment the ideal-only and headless-only keys out again.
    const std::string text =
        good({R"(calibration.source="screen.mpcdi")", "calibration.projectors=", "calibration.overlap=",
              "calibration.output=", "calibration.gamma=", R"(navigation.path="tour.json")", R"(outputs.backend="kms")",
              R"(outputs.device="/dev/dri/card1")",
              "outputs.sizes=", "outputs.png_dir=", "outputs.png_every=", "outputs.composite="});
    const KioskConfig c = parse(text);
    EXPECT_EQ(c.calibration.mpcdi, dir_ / "screen.mpcdi");
    EXPECT_EQ(c.navigation.path, (dir_ / "tour.json").string());
    EXPECT_EQ(c.outputs.backend, OutputKind::kms);
    EXPECT_EQ(c.outputs.device, fs::path("/dev/dri/card1"));
}

TEST_F(KioskConfigTest, CalibrationWatchAndTheStatusFile) {
    const KioskConfig plain = parse(good());
    EXPECT_TRUE(plain.stats.status_file.empty()) << "no status file unless configured";
    EXPECT_DOUBLE_EQ(plain.stats.status_period_s, 1.0);
    const std::string mpcdi =
        good({R"(calibration.source="screen.mpcdi")",
              "calibration.projectors=", "calibration.overlap=", "calibration.output=", "calibration.gamma="});
    EXPECT_TRUE(parse(mpcdi).calibration.watch) << "an MPCDI file is swapped in when it changes by default";
    EXPECT_TRUE(plain.stats.metrics_file.empty()) << "no metrics file unless configured";
    const KioskConfig c = parse(good({R"(stats.status_file="run/kiosk-status.json")", "stats.status_period_s=0.5",
                                      R"(stats.metrics_file="run/kiosk.prom")"}));
    EXPECT_EQ(c.stats.status_file, dir_ / "run/kiosk-status.json");
    EXPECT_EQ(c.stats.metrics_file, dir_ / "run/kiosk.prom");
    EXPECT_DOUBLE_EQ(c.stats.status_period_s, 0.5);
    EXPECT_NE(error_of(good({"stats.status_period_s=0.01"})).find("[stats].status_period_s"), std::string::npos);
    EXPECT_NE(error_of(good({"calibration.watch=false"})).find("[calibration].watch"), std::string::npos)
        << "watch means nothing for the ideal layout";
}

TEST_F(KioskConfigTest, SelfcalIsOffByDefaultAndNeedsAnMpcdiItsModelsAndALockedCamera) {
    EXPECT_FALSE(parse(good()).selfcal.enabled);
    std::ofstream(dir_ / "rig.toml") << "x";
    const std::vector<std::string> mpcdi = {R"(calibration.source="screen.mpcdi")", "calibration.projectors=",
                                            "calibration.overlap=", "calibration.output=", "calibration.gamma="};
    const auto with = [&](std::vector<std::string> more) {
        std::vector<std::string> all = mpcdi;
        all.insert(all.end(), more.begin(), more.end());
        return good(all);
    };
    // Enabled without the models file beside the MPCDI: refused naming the key and the path.
    const std::string no_models = error_of(with({"selfcal.enabled=true", R"(selfcal.camera="rig:rig.toml")"}));
    EXPECT_NE(no_models.find("[selfcal].models is required: '" + (dir_ / "screen.models.json").string()),
              std::string::npos)
        << no_models;
    std::ofstream(dir_ / "screen.models.json") << "x";
    const KioskConfig rig =
        parse(with({"selfcal.enabled=true", R"(selfcal.camera="rig:rig.toml")", "selfcal.rate_hz=1", "selfcal.hold_s=1",
                    "selfcal.transition_s=0.5", "selfcal.drift_threshold_px=0.8", "selfcal.pattern=true",
                    "selfcal.pattern_amplitude=0.05"}));
    EXPECT_TRUE(rig.selfcal.enabled);
    EXPECT_TRUE(rig.selfcal.pattern);
    EXPECT_DOUBLE_EQ(rig.selfcal.pattern_amplitude, 0.05);
    EXPECT_EQ(rig.selfcal.kind, SelfcalConfig::CameraKind::rig);
    EXPECT_EQ(rig.selfcal.rig, dir_ / "rig.toml");
    EXPECT_EQ(rig.selfcal.models, dir_ / "screen.models.json");
    EXPECT_DOUBLE_EQ(rig.selfcal.rate_hz, 1.0);
    EXPECT_DOUBLE_EQ(rig.selfcal.hold_s, 1.0);
    EXPECT_DOUBLE_EQ(rig.selfcal.transition_s, 0.5);
    EXPECT_DOUBLE_EQ(rig.selfcal.drift_threshold_px, 0.8);
    // A V4L2 camera: exposure and gain locked unless given a value; "auto" and "keep" refused.
    const KioskConfig v4l2 = parse(with({"selfcal.enabled=true", R"(selfcal.camera="v4l2:/dev/video7")"}));
    EXPECT_EQ(v4l2.selfcal.kind, SelfcalConfig::CameraKind::v4l2);
    EXPECT_EQ(v4l2.selfcal.source.device, "/dev/video7");
    EXPECT_EQ(v4l2.selfcal.source.controls.exposure.mode, ControlSetting::Mode::lock);
    EXPECT_EQ(v4l2.selfcal.source.controls.gain.mode, ControlSetting::Mode::lock);
    EXPECT_TRUE(v4l2.selfcal.source.controls.exposure.required);
    const KioskConfig manual = parse(
        with({"selfcal.enabled=true", R"(selfcal.camera="v4l2:/dev/video7")", "selfcal.camera_exposure_us=20000"}));
    EXPECT_EQ(manual.selfcal.source.controls.exposure.mode, ControlSetting::Mode::manual);
    EXPECT_DOUBLE_EQ(manual.selfcal.source.controls.exposure.value, 20000.0);
    const std::vector<std::pair<std::vector<std::string>, std::string>> bad = {
        {{"selfcal.enabled=true", R"(selfcal.camera="v4l2:/dev/video7")", R"(selfcal.camera_exposure_us="auto")"},
         "[selfcal].camera_exposure_us: the screen camera's camera_exposure_us must be \"lock\" or a value"},
        {{"selfcal.enabled=true", R"(selfcal.camera="v4l2:/dev/video7")", R"(selfcal.camera_gain="keep")"},
         "[selfcal].camera_gain: the screen camera's camera_gain must be"},
        {{"selfcal.enabled=true", R"(selfcal.camera="rig:rig.toml")", "selfcal.rate_hz=5"},
         "[selfcal].rate_hz = 5 is outside (0, 2] Hz"},
        {{"selfcal.enabled=true", R"(selfcal.camera="rig:rig.toml")", "selfcal.pattern_amplitude=0.5"},
         "[selfcal].pattern_amplitude = 0.5 is outside (0, 0.2]"},
        {{"selfcal.enabled=true", R"(selfcal.camera="rig:absent.toml")"}, "[selfcal].camera: rig file"},
        {{"selfcal.enabled=true", R"(selfcal.camera="libcamera:")"}, "[selfcal].camera: 'libcamera:' is not"},
        {{"selfcal.enabled=true"}, "[selfcal].camera is required"},
        {{"selfcal.enabled=true", R"(selfcal.camera="rig:rig.toml")", R"(selfcal.camera_size="640x480")"},
         "[selfcal].camera_size: only with a \"v4l2:\" camera"},
    };
    for (const auto& [overrides, expected] : bad) {
        const std::string message = error_of(with(overrides));
        EXPECT_NE(message.find(expected), std::string::npos) << "got: " << message << "\nexpected: " << expected;
    }
    // The ideal layout cannot be self-recalibrated (nothing to write back, no fitted models).
    const std::string ideal = error_of(good({"selfcal.enabled=true", R"(selfcal.camera="rig:rig.toml")"}));
    EXPECT_NE(ideal.find("[selfcal].enabled = true needs [calibration].source to be an MPCDI file"), std::string::npos)
        << ideal;
}

class KioskConfigBadField : public KioskConfigTest, public ::testing::WithParamInterface<BadField> {};

TEST_P(KioskConfigBadField, NamesTheFileTheFieldAndTheLimit) {
    const BadField& bad = GetParam();
    const std::string message = error_of(replace(good(), bad.from, bad.to));
    ASSERT_FALSE(message.empty()) << "accepted: " << bad.to;
    EXPECT_EQ(message.rfind(name().string(), 0), 0u) << message;  // starts with the file
    EXPECT_NE(message.find(bad.expected), std::string::npos) << message;
}

INSTANTIATE_TEST_SUITE_P(
    EveryField, KioskConfigBadField,
    ::testing::Values(
        BadField{R"(endpoint = "[fd00:6d6f::1]:7443")", R"(endpoint = "fd00:6d6f::1:7443")", "[farm].endpoint: "},
        BadField{R"(endpoint = "[fd00:6d6f::1]:7443")", R"(endpoint = "[fd00:6d6f::1]:0")",
                 "[farm].endpoint: '[fd00:6d6f::1]:0' has port 0"},
        BadField{R"(endpoint = "[fd00:6d6f::1]:7443")", R"(endpoint = "[::]:7443")", "is the wildcard address"},
        BadField{R"(endpoint = "[fd00:6d6f::1]:7443")", R"(endpoint = 7443)",
                 "[farm].endpoint: expected a string, got an integer"},
        BadField{R"(endpoint = "[fd00:6d6f::1]:7443")", R"(endpoints = "[fd00:6d6f::1]:7443")",
                 "[farm].endpoint is required"},
        BadField{R"(server_name = "farm-1")", R"(server_name = ["farm-1"])", "[farm].server_name: expected a string"},
        BadField{R"(ca = "pki/ca.pem")", R"(ca = "pki/missing.pem")", "[farm].ca: '"},
        BadField{R"(ca = "pki/ca.pem")", R"(ca = "pki")", "is not a regular file"},
        BadField{R"(cert = "pki/appliance-a.pem")", R"(cert = "")", "[farm].cert: empty path"},
        BadField{R"(key = "pki/appliance-a.key")", R"(# no key)", "[farm].key is required"},
        BadField{"rate_hz = 25", "rate_hz = 0", "[display].rate_hz = 0 is outside [0.5, 240] Hz"},
        BadField{"rate_hz = 25", "rate_hz = 1000.0", "[display].rate_hz = 1000 is outside"},
        BadField{"rate_hz = 25", "rate_hz = nan", "[display].rate_hz = nan is outside"},
        BadField{"flip_timeout_s = 12", "flip_timeout_s = 0.5", "[display].flip_timeout_s = 0.5 is outside 0 (off)"},
        BadField{"flip_timeout_s = 12", "flip_timeout_s = 601", "[display].flip_timeout_s = 601 is outside"},
        BadField{"rate_hz = 25", "rate_hz = \"fast\"", "[display].rate_hz: expected a number, got a string"},
        BadField{"late_warp_duty = 1.0", "late_warp_duty = 0", "[display].late_warp_duty = 0 is outside (0, 1]"},
        BadField{R"(backend = "headless")", R"(backend = "x11")",
                 "[outputs].backend: 'x11' is not one of headless, kms"},
        BadField{R"(sizes = ["320x240", "320x240", "320x240"])", R"(sizes = ["320x240", "320x", "320x240"])",
                 "[outputs].sizes[1]: '320x' is not WIDTHxHEIGHT"},
        BadField{R"(sizes = ["320x240", "320x240", "320x240"])", R"(sizes = ["0x240"])",
                 "[outputs].sizes[0] = '0x240' is outside [1, 16384]"},
        BadField{R"(sizes = ["320x240", "320x240", "320x240"])", R"(sizes = ["99999x240"])", "[outputs].sizes[0]"},
        BadField{R"(sizes = ["320x240", "320x240", "320x240"])", R"(sizes = [])",
                 "[outputs].sizes: 0 outputs is outside [1, 64]"},
        BadField{R"(sizes = ["320x240", "320x240", "320x240"])", R"(sizes = "320x240")",
                 "[outputs].sizes: expected an array"},
        BadField{"png_every = 5", "png_every = 0", "[outputs].png_every = 0 is outside [1, 1000000]"},
        BadField{"png_every = 5", "png_every = 2.5", "[outputs].png_every: expected an integer, got a float"},
        BadField{"composite = true", "composite = 1", "[outputs].composite: expected true or false"},
        BadField{"composite = true", "composite = true\ndevice = \"/dev/dri/card0\"",
                 "[outputs].device: only with backend = \"kms\""},
        BadField{"composite = true", "composite = true\ncolour = 1",
                 "[outputs].colour: unknown field (known: backend, device"},
        BadField{R"(source = "ideal")", R"(source = "missing.mpcdi")", "[calibration].source: '"},
        BadField{R"(source = "ideal")", R"(source = "screen.mpcdi")",
                 "[calibration].projectors: only with source = \"ideal\""},
        BadField{"projectors = 3", "projectors = 0", "[calibration].projectors = 0 is outside [1, 64]"},
        BadField{"projectors = 3", "projectors = 65", "[calibration].projectors = 65 is outside [1, 64]"},
        BadField{"overlap = 0.2", "overlap = 0.5", "[calibration].overlap = 0.5 is outside [0, 0.5)"},
        BadField{"overlap = 0.2", "overlap = -0.1", "[calibration].overlap = -0.1 is outside"},
        BadField{R"(output = "320x240")", R"(output = "320 x 240")",
                 "[calibration].output: '320 x 240' is not WIDTHxHEIGHT"},
        BadField{"gamma = 2.4", "gamma = 0", "[calibration].gamma = 0 is outside (0, 10]"},
        BadField{R"(content = "480x270")", R"(content = "8x8")", "[quality].content = '8x8' is outside [16, 16384]"},
        BadField{"spp = 2", "spp = 0", "[quality].spp = 0 is outside [1, 4096]"},
        BadField{"spp = 2", "spp = 1.5", "[quality].spp: expected an integer, got a float"},
        BadField{"jpeg_quality = 90", "jpeg_quality = 101", "[quality].jpeg_quality = 101 is outside [1, 100]"},
        BadField{"bounces = 1", "bounces = 65", "[quality].bounces = 65 is outside [0, 64]"},
        BadField{"ao_samples = 4", "ao_samples = -1", "[quality].ao_samples = -1 is outside [0, 1024]"},
        BadField{"area_light_samples = 2", "area_light_samples = 0",
                 "[quality].area_light_samples = 0 is outside [1, 1024]"},
        BadField{"radius_m = 3.5", "radius_m = 0", "[screen].radius_m = 0 is outside (0, 1000] m"},
        BadField{"arc_deg = 160", "arc_deg = 400", "[screen].arc_deg = 400 is outside (0, 360] degrees"},
        BadField{"bottom_m = 0.1", "bottom_m = inf", "[screen].bottom_m = inf is outside"},
        BadField{"top_m = 2.9", "top_m = 0.1", "[screen].top_m = 0.1 must be above [screen].bottom_m = 0.1"},
        BadField{"guard_deg = 5", "guard_deg = 101",
                 "[screen].guard_deg = 101 is outside [0, 100] degrees: arc_deg + 2 * guard_deg <= 360"},
        BadField{"guard_deg = 5", "guard_deg = -1", "[screen].guard_deg = -1 is outside [0, 100] degrees"},
        BadField{R"(path = "orbit")", R"(path = "nowhere.json")", "[navigation].path: '"},
        BadField{R"(path = "orbit")", R"(path = "")", "[navigation].path: empty"},
        BadField{"path_frames = 120", "path_frames = 1", "[navigation].path_frames = 1 is outside [2, 1000000]"},
        BadField{"start = [0.0, 0.0, 4.0]", "start = [0.0, 4.0]", "[navigation].start: expected [x, y, z]"},
        BadField{"start = [0.0, 0.0, 4.0]", "start = [0.0, \"a\", 4.0]", "[navigation].start[1]: expected a number"},
        BadField{"start = [0.0, 0.0, 4.0]", "start = [0.0, 0.0, 1e12]",
                 "[navigation].start[2] = 1000000000000 is outside"},
        BadField{"start_yaw_deg = 10", "start_yaw_deg = 4000",
                 "[navigation].start_yaw_deg = 4000 is outside [-3600, 3600]"},
        BadField{"eye_height_m = 1.5", "eye_height_m = 0", "[navigation].eye_height_m = 0 is outside (0, 100] m"},
        BadField{"log_period_s = 2.5", "log_period_s = 0", "[stats].log_period_s = 0 is outside [0.1, 86400] s"},
        BadField{R"(file = "out/stats.json")", "file = 3", "[stats].file: expected a string"},
        BadField{"[display]", "[displays]", "[displays]: unknown section (known: farm, display"},
        BadField{"rate_hz = 25", "[display.rate]\nhz = 25",
                 "[display].rate: unknown field (known: rate_hz, late_warp_duty, flip_timeout_s)"},
        BadField{"rate_hz = 25", "rate_hz = = 25", "not valid TOML"}));

TEST_F(KioskConfigTest, MessagesCarryTheLineOfTheOffendingValue) {
    const std::string text = good();
    const std::string message = error_of(replace(text, "spp = 2", "spp = 0"));
    const auto line = 1 + std::count(text.begin(), text.begin() + static_cast<long>(text.find("spp = 2")), '\n');
    EXPECT_NE(message.find(name().string() + ":" + std::to_string(line) + ": [quality].spp"), std::string::npos)
        << message;
}

// toml11 recurses once per nesting level without a limit: 20000 levels overflowed the stack
// (found by fuzzing, tests/fuzz kiosk_config). The guard refuses them with the file and line; at
// the guard's limit toml11 parses the value and the field check reports it.
// Found by fuzzing (tests/fuzz/corpus/kiosk_config/regression-literal-string-invalid-utf8.toml):
// toml11 3.7 read out of bounds on a literal string holding bytes that are not UTF-8.
TEST_F(KioskConfigTest, ALiteralStringThatIsNotUtf8IsRefusedWithItsLineNotACrash) {
    const std::string text = good();
    const std::string field = R"(file = "out/stats.json")";
    ASSERT_NE(text.find(field), std::string::npos);
    const auto line = 1 + std::count(text.begin(), text.begin() + static_cast<long>(text.find(field)), '\n');
    for (const std::string value : {"'out\xFF.json'", "'''out\xC0\xAF.json'''", "\"out\xED\xA0\x80.json\""}) {
        const std::string e = error_of(replace(text, field, "file = " + value));
        EXPECT_NE(e.find(name().string() + ":" + std::to_string(line) + ": byte "), std::string::npos) << e;
        EXPECT_NE(e.find("is not UTF-8"), std::string::npos) << e;
    }
    EXPECT_EQ(error_of(replace(text, field, "file = 'out/\xC3\xA9t\xC3\xA9.json'")), "") << "UTF-8 is fine";
    try {
        (void)apply_config_overrides(text, {"stats.file='\xFF'"});
        ADD_FAILURE() << "no error for an override that is not UTF-8";
    } catch (const KioskConfigError& e) {
        EXPECT_NE(std::string(e.what()).find("is not UTF-8"), std::string::npos) << e.what();
    }
}

TEST_F(KioskConfigTest, ADeeplyNestedValueIsRefusedWithItsLineNotACrash) {
    const std::string text = good();
    const std::string field = R"(file = "out/stats.json")";
    ASSERT_NE(text.find(field), std::string::npos);
    const auto line = 1 + std::count(text.begin(), text.begin() + static_cast<long>(text.find(field)), '\n');
    const auto nested = [](int levels) { return std::string(levels, '[') + std::string(levels, ']'); };
    const std::string deep = error_of(replace(text, field, "file = " + nested(20000)));
    EXPECT_NE(deep.find(name().string() + ":" + std::to_string(line) + ": tables or arrays nested deeper than " +
                        std::to_string(kMaxTomlNesting)),
              std::string::npos)
        << deep;
    const std::string at_limit = error_of(replace(text, field, "file = " + nested(kMaxTomlNesting)));
    EXPECT_NE(at_limit.find("[stats].file: expected a string"), std::string::npos) << at_limit;
    try {
        (void)apply_config_overrides(text, {"stats.file=" + nested(kMaxTomlNesting + 1)});
        ADD_FAILURE() << "no error for an override nested " << kMaxTomlNesting + 1 << " deep";
    } catch (const KioskConfigError& e) {
        EXPECT_NE(std::string(e.what()).find("nests tables or arrays deeper than 32"), std::string::npos) << e.what();
    }
    // The worst the guard lets through: 32 inline tables, the one at depth d under a key of 32 - d
    // dots (528 table levels); toml11 must parse it (also under ASan), the field check refuse it.
    std::string worst;
    for (int depth = 1; depth <= kMaxTomlNesting; ++depth) {
        worst += "{a";
        for (int dot = 0; dot < kMaxTomlNesting - depth; ++dot) worst += ".a";
        worst += " = ";
    }
    worst += "1" + std::string(kMaxTomlNesting, '}');
    ASSERT_FALSE(toml_nesting_excess("file = " + worst).has_value());
    ASSERT_TRUE(toml_nesting_excess("file = {a." + worst.substr(1)).has_value());
    const std::string worst_error = error_of(replace(text, field, "file = " + worst));
    EXPECT_NE(worst_error.find("[stats].file: expected a string"), std::string::npos) << worst_error;
}

TEST_F(KioskConfigTest, MissingFarmSectionAndMissingFileAreErrors) {
    EXPECT_NE(error_of("[display]\nrate_hz = 30\n").find("[farm] is required"), std::string::npos);
    try {
        (void)load_kiosk_config(dir_ / "absent.toml");
        ADD_FAILURE() << "no error for a missing file";
    } catch (const KioskConfigError& e) {
        EXPECT_NE(std::string(e.what()).find("absent.toml: no such file"), std::string::npos) << e.what();
    }
}

TEST_F(KioskConfigTest, AKnownSectionMustBeATable) {
    const std::string message = error_of(R"(stats = 3
[farm]
endpoint = "[::1]:7443"
ca = "pki/ca.pem"
cert = "pki/appliance-a.pem"
key = "pki/appliance-a.key"
)");
    EXPECT_NE(message.find("[stats]: expected a table, got an integer"), std::string::npos) << message;
}

TEST_F(KioskConfigTest, LoadReadsTheFile) {
    std::ofstream(name()) << good();
    EXPECT_EQ(load_kiosk_config(name()).quality.jpeg_quality, 90);
}

// The sample shipped in kiosk/ must stay valid: its /etc/mogao paths are pointed at this test's
// folder (the parser checks that the files exist).
TEST_F(KioskConfigTest, TheExampleFileIsValid) {
    std::ifstream in(fs::path(MOGAO_SOURCE_DIR) / "kiosk/config/kiosk.example.toml");
    ASSERT_TRUE(in) << "kiosk/config/kiosk.example.toml not found";
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string prefix = "/etc/mogao/";
    for (auto at = text.find(prefix); at != std::string::npos; at = text.find(prefix, at)) {
        text.replace(at, prefix.size(), (dir_ / "etc").string() + "/");
    }
    fs::create_directories(dir_ / "etc/pki");
    for (const char* f :
         {"etc/pki/ca.pem", "etc/pki/appliance-museum-1.pem", "etc/pki/appliance-museum-1.key", "etc/screen.mpcdi"}) {
        std::ofstream(dir_ / f) << "x";
    }
    const KioskConfig c = parse(text);
    EXPECT_EQ(c.outputs.backend, OutputKind::kms);
    EXPECT_EQ(c.calibration.mpcdi, dir_ / "etc/screen.mpcdi");
    EXPECT_EQ(c.navigation.path, "walk");
}

}  // namespace
}  // namespace mogao
