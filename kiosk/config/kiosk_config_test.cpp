// SPDX-License-Identifier: Apache-2.0
#include "kiosk/config/kiosk_config.h"

#include "common/quality_preset.h"
#include "common/toml_nesting.h"

#include "kiosk/config/config_overrides.h"

#include "appliance/tracker/camera_intrinsics.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

namespace mogao {
namespace {

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

std::string read_source_file(const char* relative) {
    std::ifstream in(fs::path(MOGAO_SOURCE_DIR) / relative);
    EXPECT_TRUE(in) << relative << " not found";
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Overrides of the shipped example that set every field (the files are made by SetUp).
const std::vector<std::string> kGood = {R"(farm.endpoint="[fd00:6d6f::1]:7443")",
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

std::string KioskConfigTest::good(const std::vector<std::string>& more) {
    std::vector<std::string> overrides = kGood;
    overrides.insert(overrides.end(), more.begin(), more.end());
    return apply_config_overrides(read_source_file("kiosk/config/kiosk.example.toml"), overrides);
}

// `text` with the first occurrence of `from` replaced by `to` (fails the test if absent).
std::string replace(std::string text, const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << "test bug: '" << from << "' is not in the configuration";
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return text;
}

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

struct BadField {
    const char* from;
    const char* to;
    const char* expected;  // substring of the message, after "<file>:<line>: "
};

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
                 "[display].rate: unknown field (known: rate_hz, flip_timeout_s)"},
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

// --- [navigation] source = "tracking" ---------------------------------------------------------

// good() with the tracking source: the scripted visitor's keys out, `navigation` in.
std::string tracking(std::vector<std::string> navigation) {
    navigation.insert(navigation.begin(),
                      {"navigation.path=", "navigation.path_frames=", R"(navigation.source="tracking")"});
    return KioskConfigTest::good(navigation);
}

// Every tracking field set, the two tables included.
std::string full_tracking() {
    return tracking({R"(navigation.camera="replay:seq")",
                     "navigation.camera_fps=25",
                     "navigation.tag_size_m=0.12",
                     "navigation.tag_id=3",
                     R"(navigation.replay_end="idle")",
                     R"(navigation.detector.family="tag25h9")",
                     "navigation.detector.decimation=1.5",
                     "navigation.detector.blur_sigma=0.0",
                     "navigation.detector.refine_edges=false",
                     "navigation.detector.min_white_black_diff=10",
                     "navigation.detector.decode_sharpening=0.5",
                     "navigation.detector.max_hamming=1",
                     "navigation.detector.threads=2",
                     "navigation.roi.enabled=false",
                     "navigation.roi.full_search_every=30",
                     "navigation.roi.window_tag_px=0",
                     "navigation.roi.idle_after_s=2.5",
                     "navigation.roi.idle_search_period_s=0.25",
                     "navigation.control.rest_distance_m=0.45",
                     "navigation.control.rest_yaw_deg=2",
                     "navigation.control.turn_dead_zone_deg=5",
                     "navigation.control.turn_full_scale_deg=25",
                     "navigation.control.turn_max_deg_s=60",
                     "navigation.control.forward_max_m_s=0.5",
                     "navigation.control.strafe_max_m_s=0.3",
                     "navigation.control.pitch=true",
                     "navigation.control.max_angular_accel_deg_s2=90",
                     "navigation.control.hold_s=0.2",
                     "navigation.control.forget_s=1.0",
                     "navigation.control.max_dt_s=0.05"});
}

TEST_F(KioskConfigTest, ReadsTheTrackingFields) {
    const KioskConfig c = parse(full_tracking());
    const TrackingConfig& t = c.navigation.tracking;
    EXPECT_EQ(c.navigation.source, NavigationSource::tracking);
    EXPECT_EQ(t.camera, "replay:seq");
    EXPECT_EQ(t.source.kind, CameraSourceSpec::Kind::replay);
    EXPECT_EQ(t.source.folder, dir_ / "seq");
    EXPECT_DOUBLE_EQ(t.source.replay_fps, 25.0);
    EXPECT_EQ(t.intrinsics_file, dir_ / "seq/camera.json");  // the replay's own calibration by default
    EXPECT_EQ(t.intrinsics.width, 800);
    EXPECT_DOUBLE_EQ(t.intrinsics.fx, 700.0);
    EXPECT_DOUBLE_EQ(t.tag_size_m, 0.12);
    EXPECT_EQ(t.tag_id, 3);
    EXPECT_EQ(t.replay_end, ReplayEnd::idle);
    EXPECT_FALSE(t.source.loop);
    EXPECT_EQ(t.detector.family, "tag25h9");
    EXPECT_FLOAT_EQ(t.detector.decimation, 1.5f);
    EXPECT_FLOAT_EQ(t.detector.blur_sigma, 0.0f);
    EXPECT_FALSE(t.detector.refine_edges);
    EXPECT_EQ(t.detector.min_white_black_diff, 10);
    EXPECT_DOUBLE_EQ(t.detector.decode_sharpening, 0.5);
    EXPECT_EQ(t.detector.max_hamming, 1);
    EXPECT_EQ(t.detector.threads, 2);
    EXPECT_FALSE(t.roi.enabled);
    EXPECT_EQ(t.roi.full_search_every, 30);
    EXPECT_DOUBLE_EQ(t.roi.window_tag_px, 0.0);
    EXPECT_DOUBLE_EQ(t.roi.idle_after_s, 2.5);
    EXPECT_DOUBLE_EQ(t.roi.idle_search_period_s, 0.25);
    EXPECT_DOUBLE_EQ(t.roi.margin, RoiSettings{}.margin);  // not a key: as tag_tracker.h measured it
    EXPECT_DOUBLE_EQ(t.params.rest.distance_m, 0.45);
    EXPECT_DOUBLE_EQ(t.params.rest.yaw_deg, 2.0);
    EXPECT_DOUBLE_EQ(t.params.turn.dead_zone, 5.0);
    EXPECT_DOUBLE_EQ(t.params.turn.full_scale, 25.0);
    EXPECT_DOUBLE_EQ(t.params.turn.max_rate, 60.0);
    EXPECT_DOUBLE_EQ(t.params.forward.max_rate, 0.5);
    EXPECT_DOUBLE_EQ(t.params.strafe.max_rate, 0.3);
    EXPECT_TRUE(t.params.pitch.enabled);
    EXPECT_DOUBLE_EQ(t.params.max_angular_accel_deg_s2, 90.0);
    EXPECT_DOUBLE_EQ(t.params.hold_s, 0.2);
    EXPECT_DOUBLE_EQ(t.params.forget_s, 1.0);
    EXPECT_DOUBLE_EQ(t.params.max_dt_s, 0.05);
    EXPECT_DOUBLE_EQ(t.params.eye_height_m, 1.5);  // [navigation].eye_height_m
    const ViewerPose start = start_pose(c.navigation);
    EXPECT_DOUBLE_EQ(start.eye.y(), 1.5);
    EXPECT_DOUBLE_EQ(start.eye.z(), 4.0);
    EXPECT_DOUBLE_EQ(start.yaw_deg, 10.0);
}

TEST_F(KioskConfigTest, TrackingDefaultsComeFromTheLibraries) {
    const KioskConfig c = parse(tracking({R"(navigation.camera="replay:seq")"}));
    const TrackingConfig& t = c.navigation.tracking;
    EXPECT_EQ(t.replay_end, ReplayEnd::stop);
    EXPECT_EQ(t.tag_id, -1);
    EXPECT_DOUBLE_EQ(t.tag_size_m, 0.10);
    EXPECT_EQ(t.detector.family, DetectorSettings{}.family);
    EXPECT_DOUBLE_EQ(t.params.turn.max_rate, NavigationParams{}.turn.max_rate);
    EXPECT_DOUBLE_EQ(t.params.rest.distance_m, NavigationParams{}.rest.distance_m);
    EXPECT_EQ(parse(tracking({R"(navigation.camera="replay:seq")", R"(navigation.replay_end="loop")"}))
                  .navigation.tracking.source.loop,
              true);
}

TEST_F(KioskConfigTest, AV4l2CameraNeedsIntrinsicsAndRescalesThemToItsSize) {
    const KioskConfig c =
        parse(tracking({R"(navigation.camera="v4l2:/dev/video2")", R"(navigation.intrinsics="webcam.json")",
                        R"(navigation.camera_size="400x300")", "navigation.camera_fps=30"}));
    const TrackingConfig& t = c.navigation.tracking;
    EXPECT_EQ(t.source.kind, CameraSourceSpec::Kind::v4l2);
    EXPECT_EQ(t.source.device, "/dev/video2");
    EXPECT_EQ(t.source.width, 400);
    EXPECT_EQ(t.source.height, 300);
    EXPECT_EQ(t.source.fps, 30);
    EXPECT_EQ(t.intrinsics.width, 400);
    EXPECT_DOUBLE_EQ(t.intrinsics.fx, 350.0);  // a 2x2-binned mode of the calibrated sensor
    EXPECT_DOUBLE_EQ(t.intrinsics.cx, 199.5);
    const KioskConfig same =
        parse(tracking({R"(navigation.camera="v4l2:/dev/video0")", R"(navigation.intrinsics="webcam.json")"}));
    EXPECT_EQ(same.navigation.tracking.source.width, 800);  // the calibrated size by default
    EXPECT_EQ(same.navigation.tracking.source.fps, 0);
}

TEST_F(KioskConfigTest, ALibcameraCameraIsNamedLikeAnyOtherAndRunsAtItsPipelinesRate) {
    const KioskConfig c =
        parse(tracking({R"(navigation.camera="libcamera:/base/platform/vivid.0-0000")",
                        R"(navigation.intrinsics="webcam.json")", R"(navigation.camera_size="400x300")"}));
    const TrackingConfig& t = c.navigation.tracking;
    EXPECT_EQ(t.source.kind, CameraSourceSpec::Kind::libcamera);
    EXPECT_EQ(t.source.camera_id, "/base/platform/vivid.0-0000");
    EXPECT_EQ(t.source.width, 400);
    EXPECT_EQ(t.intrinsics.width, 400);
    EXPECT_EQ(parse(tracking({R"(navigation.camera="libcamera:")", R"(navigation.intrinsics="webcam.json")"}))
                  .navigation.tracking.source.width,
              800);  // the calibrated size by default
    const std::string message = error_of(tracking(
        {R"(navigation.camera="libcamera:")", R"(navigation.intrinsics="webcam.json")", "navigation.camera_fps=30"}));
    EXPECT_NE(message.find("camera_fps: only with a \"replay:\" or \"v4l2:\" camera"), std::string::npos) << message;
}

TEST_F(KioskConfigTest, LiveCameraControlsDefaultToAShortExposureAndAreRequiredWhenWritten) {
    const KioskConfig c =
        parse(tracking({R"(navigation.camera="v4l2:/dev/video0")", R"(navigation.intrinsics="webcam.json")"}));
    const CameraControls& d = c.navigation.tracking.source.controls;
    EXPECT_EQ(d.exposure.mode, ControlSetting::Mode::manual);
    EXPECT_DOUBLE_EQ(d.exposure.value, kDefaultExposureUs);
    EXPECT_FALSE(d.exposure.required);  // a camera without manual exposure keeps its own
    EXPECT_EQ(d.gain.mode, ControlSetting::Mode::keep);
    EXPECT_EQ(d.white_balance.mode, ControlSetting::Mode::keep);
    EXPECT_FALSE(c.navigation.tracking.source.colour);
    EXPECT_NE(d.exposure.name.find("[navigation].camera_exposure_us"), std::string::npos) << d.exposure.name;

    const KioskConfig set =
        parse(tracking({R"(navigation.camera="v4l2:/dev/video0")", R"(navigation.intrinsics="webcam.json")",
                        "navigation.camera_exposure_us=4000", R"(navigation.camera_gain="auto")",
                        R"(navigation.camera_white_balance_k="lock")", "navigation.camera_colour=true"}));
    const CameraControls& w = set.navigation.tracking.source.controls;
    EXPECT_EQ(w.exposure.mode, ControlSetting::Mode::manual);
    EXPECT_DOUBLE_EQ(w.exposure.value, 4000);
    EXPECT_TRUE(w.exposure.required);
    EXPECT_EQ(w.gain.mode, ControlSetting::Mode::automatic);
    EXPECT_TRUE(w.gain.required);
    EXPECT_EQ(w.white_balance.mode, ControlSetting::Mode::lock);
    EXPECT_TRUE(set.navigation.tracking.source.colour);
    // The device's own range is checked when the camera opens; the message then names this key.
    EXPECT_EQ(w.gain.name, name().string() + ": [navigation].camera_gain");
}

TEST_F(KioskConfigTest, CameraControlKeysAreCheckedAndRefusedForAReplay) {
    const auto live = [](const std::string& line) {
        return tracking({R"(navigation.camera="v4l2:/dev/video0")", R"(navigation.intrinsics="webcam.json")", line});
    };
    std::string message = error_of(live("navigation.camera_exposure_us=0"));
    EXPECT_NE(message.find("[navigation].camera_exposure_us = 0 is outside (0, 1e6] us"), std::string::npos) << message;
    message = error_of(live(R"(navigation.camera_gain="max")"));
    EXPECT_NE(message.find("[navigation].camera_gain: 'max' is not one of auto, lock, keep or a number in [0, 1e6]"),
              std::string::npos)
        << message;
    message = error_of(live("navigation.camera_white_balance_k=500"));
    EXPECT_NE(message.find("[navigation].camera_white_balance_k = 500 is outside [1000, 20000] K"), std::string::npos)
        << message;
    message = error_of(live(R"(navigation.camera_colour="yes")"));
    EXPECT_NE(message.find("[navigation].camera_colour: expected true or false"), std::string::npos) << message;
    message = error_of(tracking({R"(navigation.camera="replay:seq")", "navigation.camera_exposure_us=4000"}));
    EXPECT_NE(message.find("[navigation].camera_exposure_us: only with a live camera"), std::string::npos) << message;
}

class KioskTrackingBadField : public KioskConfigTest, public ::testing::WithParamInterface<BadField> {};

TEST_P(KioskTrackingBadField, NamesTheFileTheFieldAndTheReason) {
    const BadField& bad = GetParam();
    const std::string message = error_of(replace(full_tracking(), bad.from, bad.to));
    ASSERT_FALSE(message.empty()) << "accepted: " << bad.to;
    EXPECT_EQ(message.rfind(name().string(), 0), 0u) << message;
    EXPECT_NE(message.find(bad.expected), std::string::npos) << message;
}

INSTANTIATE_TEST_SUITE_P(
    EveryTrackingField, KioskTrackingBadField,
    ::testing::Values(
        BadField{R"(source = "tracking")", R"(source = "tag")",
                 "[navigation].source: 'tag' is not one of path, tracking"},
        BadField{R"(source = "tracking")", R"(source = "path")",
                 "[navigation].camera: only with source = \"tracking\""},
        BadField{R"(source = "tracking")", "source = \"tracking\"\npath = \"walk\"",
                 "[navigation].path: only with source = \"path\""},
        BadField{R"(camera = "replay:seq")", "# no camera", "[navigation].camera is required"},
        BadField{R"(camera = "replay:seq")", R"(camera = "seq")",
                 "[navigation].camera: 'seq' is none of \"replay:<folder>\", \"v4l2:/dev/videoN\", "
                 "\"libcamera:[<camera id>]\""},
        BadField{R"(camera = "replay:seq")", R"(camera = "replay:")", "[navigation].camera: 'replay:' needs a folder"},
        BadField{R"(camera = "replay:seq")", R"(camera = "replay:nowhere")", "[navigation].camera: replay folder '"},
        BadField{R"(camera = "replay:seq")", R"(camera = "v4l2:video0")",
                 "[navigation].camera: 'video0' is not an absolute device path"},
        BadField{R"(camera = "replay:seq")", R"(camera = "v4l2:/dev/video0")",
                 "[navigation].replay_end: only with a \"replay:\" camera"},
        BadField{R"(camera = "replay:seq")", "camera = \"replay:.\"", "[navigation].intrinsics is required"},
        BadField{"camera_fps = 25", "camera_fps = 0", "[navigation].camera_fps = 0 is outside (0, 1000] Hz"},
        BadField{"camera_fps = 25", "camera_fps = 25\ncamera_size = \"640x480\"",
                 "[navigation].camera_size: only with a live camera, \"v4l2:\" or \"libcamera:\""},
        BadField{"camera_fps = 25", "camera_fps = 25\nintrinsics = \"absent.json\"", "[navigation].intrinsics: '"},
        BadField{"camera_fps = 25", "camera_fps = 25\nintrinsics = \"broken.json\"", "[navigation].intrinsics: "},
        BadField{"tag_size_m = 0.12", "tag_size_m = 0", "[navigation].tag_size_m = 0 is outside (0, 10] m"},
        BadField{"tag_id = 3", "tag_id = -2", "[navigation].tag_id = -2 is outside [0, 1000000]"},
        BadField{R"(replay_end = "idle")", R"(replay_end = "rewind")",
                 "[navigation].replay_end: 'rewind' is not one of stop, loop, idle"},
        BadField{R"(family = "tag25h9")", R"(family = "qr")", "[navigation.detector].family: "},
        BadField{"decimation = 1.5", "decimation = 9", "[navigation.detector].decimation = 9 is outside [1, 8]"},
        BadField{"max_hamming = 1", "max_hamming = 3", "[navigation.detector].max_hamming = 3 is outside [0, 2]"},
        BadField{"threads = 2", "thread = 2", "[navigation.detector].thread: unknown field (known: family"},
        BadField{"window_tag_px = 0", "window_tag_px = 2",
                 "[navigation.roi].window_tag_px = 2 is outside 0 or [4, 1000] px"},
        BadField{"idle_search_period_s = 0.25", "idle_search_period_s = -1",
                 "[navigation.roi].idle_search_period_s = -1 is outside [0, 3600] s"},
        BadField{"full_search_every = 30", "full_search_every = 1.5", "[navigation.roi].full_search_every"},
        BadField{"enabled = false", "enable = false", "[navigation.roi].enable: unknown field (known: enabled"},
        BadField{"rest_distance_m = 0.45", "rest_distance_m = 0",
                 "[navigation.control].rest_distance_m = 0 is outside (0, 1e6] m"},
        BadField{"turn_dead_zone_deg = 5", "turn_dead_zone_deg = 40", "[navigation.control]: NavigationParams.turn"},
        BadField{"hold_s = 0.2", "hold_s = 2", "[navigation.control]: NavigationParams: need 0 <= hold_s"},
        BadField{"pitch = true", "pitch = 1", "[navigation.control].pitch: expected true or false"},
        BadField{"max_dt_s = 0.05", "max_dt = 0.05", "[navigation.control].max_dt: unknown field (known: rest_yaw_deg"},
        BadField{"[navigation.control]", "[navigation.controls]", "[navigation].controls: unknown field"}));

TEST_F(KioskConfigTest, ThePathSourceRejectsTrackingTables) {
    const std::string text = good({"navigation.detector.threads=1"});
    EXPECT_NE(error_of(text).find("[navigation].detector: only with source = \"tracking\""), std::string::npos)
        << error_of(text);
}

// The commented tracking example of kiosk.example.toml, uncommented, is valid too: every "# key ="
// line after `source = "tracking"` and the two tables.
TEST_F(KioskConfigTest, TheExampleFilesTrackingBlockIsValid) {
    std::string text = read_source_file("kiosk/config/kiosk.example.toml");
    const std::string prefix = "/etc/mogao/";
    for (auto at = text.find(prefix); at != std::string::npos; at = text.find(prefix, at)) {
        text.replace(at, prefix.size(), (dir_ / "etc").string() + "/");
    }
    fs::create_directories(dir_ / "etc/pki");
    for (const char* f :
         {"etc/pki/ca.pem", "etc/pki/appliance-museum-1.pem", "etc/pki/appliance-museum-1.key", "etc/screen.mpcdi"}) {
        std::ofstream(dir_ / f) << "x";
    }
    fs::copy_file(dir_ / "webcam.json", dir_ / "etc/camera.json");
    text = replace(text, "source = \"path\"", "source = \"tracking\"");
    text = replace(text, "path = \"walk\"\n", "");
    text = replace(text, "path_frames = 900", "# path_frames");
    // Uncomment the tracking block in place, from "# camera =" to [stats]: "# key = value" lines
    // and "# [table]" headers (comment-only lines stay comments).
    const auto from = text.find("# camera = ");
    const auto stats = text.find("[stats]");
    ASSERT_NE(from, std::string::npos);
    ASSERT_NE(stats, std::string::npos);
    std::string block;
    std::istringstream lines(text.substr(from, stats - from));
    for (std::string line; std::getline(lines, line);) {
        const auto eq = line.find(" = ");
        const bool key = line.rfind("# ", 0) == 0 && eq != std::string::npos && line.find_first_of(" ", 2) == eq;
        block += (key || line.rfind("# [", 0) == 0 ? line.substr(2) : line) + "\n";
    }
    text = text.substr(0, from) + block + text.substr(stats);
    text = replace(text, "\nreplay_end = ", "\n# replay only: replay_end = ");  // the example's camera is v4l2
    const KioskConfig c = parse(text);
    EXPECT_EQ(c.navigation.source, NavigationSource::tracking);
    EXPECT_EQ(c.navigation.tracking.source.device, "/dev/video0");
    EXPECT_EQ(c.navigation.tracking.intrinsics_file, dir_ / "etc/camera.json");
    EXPECT_EQ(c.navigation.tracking.tag_id, 0);
    EXPECT_EQ(c.navigation.tracking.detector.family, "tag36h11");
    EXPECT_DOUBLE_EQ(c.navigation.tracking.params.turn.max_rate, 45.0);
}

// The example's commented [selfcal] block, uncommented and enabled, is valid: every "# key = value"
// line between "[selfcal]" and the end of the file.
TEST_F(KioskConfigTest, TheExampleFilesSelfcalBlockIsValid) {
    std::string text = read_source_file("kiosk/config/kiosk.example.toml");
    const std::string prefix = "/etc/mogao/";
    for (auto at = text.find(prefix); at != std::string::npos; at = text.find(prefix, at)) {
        text.replace(at, prefix.size(), (dir_ / "etc").string() + "/");
    }
    fs::create_directories(dir_ / "etc/pki");
    for (const char* f : {"etc/pki/ca.pem", "etc/pki/appliance-museum-1.pem", "etc/pki/appliance-museum-1.key",
                          "etc/screen.mpcdi", "etc/screen.models.json"}) {
        std::ofstream(dir_ / f) << "x";
    }
    const auto from = text.find("[selfcal]");
    ASSERT_NE(from, std::string::npos);
    std::string block;
    std::istringstream lines(text.substr(from));
    for (std::string line; std::getline(lines, line);) {
        const auto eq = line.find(" = ");
        const bool key = line.rfind("# ", 0) == 0 && eq != std::string::npos && line.find_first_of(" ", 2) == eq;
        block += (key ? line.substr(2) : line) + "\n";
    }
    text = replace(text.substr(0, from) + block, "enabled = false", "enabled = true");
    const KioskConfig c = parse(text);
    EXPECT_TRUE(c.selfcal.enabled);
    EXPECT_EQ(c.selfcal.source.device, "/dev/video1");
    EXPECT_EQ(c.selfcal.source.width, 1280);
    EXPECT_EQ(c.selfcal.models, dir_ / "etc/screen.models.json");
    EXPECT_EQ(c.selfcal.source.controls.exposure.mode, ControlSetting::Mode::lock);
    EXPECT_DOUBLE_EQ(c.selfcal.rate_hz, 2.0);
    EXPECT_EQ(c.status.on_wall, OnWall::on_demand);
    EXPECT_DOUBLE_EQ(c.status.farm_lost_after_s, 10.0);
}

// kiosk/config/tour-tracking.overrides applied to the example, placed as the README's live tour uses it:
// out/live/ with its PKI, the sequence in out/hand-sequence.
TEST_F(KioskConfigTest, TheTourTrackingFileIsValidInItsPlace) {
    fs::create_directories(dir_ / "out/live/pki");
    for (const char* f :
         {"out/live/pki/ca.pem", "out/live/pki/appliance-museum-1.pem", "out/live/pki/appliance-museum-1.key"}) {
        std::ofstream(dir_ / f) << "x";
    }
    fs::create_directories(dir_ / "out/hand-sequence");
    fs::copy_file(dir_ / "webcam.json", dir_ / "out/hand-sequence/camera.json");
    const std::vector<std::string> overrides =
        expand_override_files({"@" + (fs::path(MOGAO_SOURCE_DIR) / "kiosk/config/tour-tracking.overrides").string()});
    ASSERT_GE(overrides.size(), 10u);
    const KioskConfig c = parse_kiosk_config(apply_config_overrides(kiosk_example_toml(), overrides),
                                             dir_ / "out/live/kiosk-tracking.toml");
    EXPECT_EQ(c.navigation.source, NavigationSource::tracking);
    EXPECT_EQ(c.navigation.tracking.source.folder, dir_ / "out/hand-sequence");
    EXPECT_EQ(c.navigation.tracking.intrinsics_file, dir_ / "out/hand-sequence/camera.json");
    EXPECT_EQ(c.navigation.tracking.replay_end, ReplayEnd::stop);
    EXPECT_EQ(c.outputs.backend, OutputKind::headless);
    EXPECT_EQ(c.outputs.png_dir, dir_ / "out/live/outputs-tracking");
    EXPECT_DOUBLE_EQ(c.navigation.tracking.params.max_dt_s, 0.5);
}

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
