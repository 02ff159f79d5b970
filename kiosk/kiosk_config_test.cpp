#include "kiosk/kiosk_config.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>

namespace mogao {
namespace {

namespace fs = std::filesystem;

// A folder with the files a configuration references (contents do not matter to the parser).
class KioskConfigTest : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("mogao-kiosk-config-" + std::to_string(::getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_ / "pki");
        for (const char* f : {"pki/ca.pem", "pki/appliance-a.pem", "pki/appliance-a.key", "screen.mpcdi", "tour.json"}) {
            std::ofstream(dir_ / f) << "x";
        }
    }
    void TearDown() override { fs::remove_all(dir_); }

    [[nodiscard]] fs::path name() const { return dir_ / "kiosk.toml"; }

    // Every field set, valid.
    static std::string good() {
        return R"([farm]
endpoint = "[fd00:6d6f::1]:7443"
server_name = "farm-1"
ca = "pki/ca.pem"
cert = "pki/appliance-a.pem"
key = "pki/appliance-a.key"

[display]
rate_hz = 25

[outputs]
backend = "headless"
sizes = ["320x240", "320x240", "320x240"]
png_dir = "out/png"
png_every = 5
composite = true

[calibration]
source = "ideal"
projectors = 3
overlap = 0.2
output = "320x240"
gamma = 2.4

[quality]
content = "480x270"
spp = 2
jpeg_quality = 90
bounces = 1
ao_samples = 4
area_light_samples = 2

[screen]
radius_m = 3.5
arc_deg = 160
bottom_m = 0.1
top_m = 2.9

[navigation]
path = "orbit"
path_frames = 120
start = [0.0, 0.0, 4.0]
start_yaw_deg = 10
eye_height_m = 1.5

[stats]
file = "out/stats.json"
log_period_s = 2.5
)";
    }

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

TEST_F(KioskConfigTest, AcceptsAnMpcdiSourceAPathFileAndKmsDevice) {
    std::string text = replace(good(), R"(source = "ideal"
projectors = 3
overlap = 0.2
output = "320x240"
gamma = 2.4)", R"(source = "screen.mpcdi")");
    text = replace(text, R"(path = "orbit")", R"(path = "tour.json")");
    text = replace(text, R"(backend = "headless"
sizes = ["320x240", "320x240", "320x240"]
png_dir = "out/png"
png_every = 5
composite = true)", R"(backend = "kms"
device = "/dev/dri/card1")");
    const KioskConfig c = parse(text);
    EXPECT_EQ(c.calibration.mpcdi, dir_ / "screen.mpcdi");
    EXPECT_EQ(c.navigation.path, (dir_ / "tour.json").string());
    EXPECT_EQ(c.outputs.backend, OutputKind::kms);
    EXPECT_EQ(c.outputs.device, fs::path("/dev/dri/card1"));
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
        BadField{R"(endpoint = "[fd00:6d6f::1]:7443")", R"(endpoint = "[fd00:6d6f::1]:0")", "[farm].endpoint: '[fd00:6d6f::1]:0' has port 0"},
        BadField{R"(endpoint = "[fd00:6d6f::1]:7443")", R"(endpoint = "[::]:7443")", "is the wildcard address"},
        BadField{R"(endpoint = "[fd00:6d6f::1]:7443")", R"(endpoint = 7443)", "[farm].endpoint: expected a string, got an integer"},
        BadField{R"(endpoint = "[fd00:6d6f::1]:7443")", R"(endpoints = "[fd00:6d6f::1]:7443")", "[farm].endpoint is required"},
        BadField{R"(server_name = "farm-1")", R"(server_name = ["farm-1"])", "[farm].server_name: expected a string"},
        BadField{R"(ca = "pki/ca.pem")", R"(ca = "pki/missing.pem")", "[farm].ca: '"},
        BadField{R"(ca = "pki/ca.pem")", R"(ca = "pki")", "is not a regular file"},
        BadField{R"(cert = "pki/appliance-a.pem")", R"(cert = "")", "[farm].cert: empty path"},
        BadField{R"(key = "pki/appliance-a.key")", R"(# no key)", "[farm].key is required"},
        BadField{"rate_hz = 25", "rate_hz = 0", "[display].rate_hz = 0 is outside [0.5, 240] Hz"},
        BadField{"rate_hz = 25", "rate_hz = 1000.0", "[display].rate_hz = 1000 is outside"},
        BadField{"rate_hz = 25", "rate_hz = nan", "[display].rate_hz = nan is outside"},
        BadField{"rate_hz = 25", "rate_hz = \"fast\"", "[display].rate_hz: expected a number, got a string"},
        BadField{R"(backend = "headless")", R"(backend = "x11")", "[outputs].backend: 'x11' is not one of headless, kms"},
        BadField{R"(sizes = ["320x240", "320x240", "320x240"])", R"(sizes = ["320x240", "320x", "320x240"])", "[outputs].sizes[1]: '320x' is not WIDTHxHEIGHT"},
        BadField{R"(sizes = ["320x240", "320x240", "320x240"])", R"(sizes = ["0x240"])", "[outputs].sizes[0] = '0x240' is outside [1, 16384]"},
        BadField{R"(sizes = ["320x240", "320x240", "320x240"])", R"(sizes = ["99999x240"])", "[outputs].sizes[0]"},
        BadField{R"(sizes = ["320x240", "320x240", "320x240"])", R"(sizes = [])", "[outputs].sizes: 0 outputs is outside [1, 64]"},
        BadField{R"(sizes = ["320x240", "320x240", "320x240"])", R"(sizes = "320x240")", "[outputs].sizes: expected an array"},
        BadField{"png_every = 5", "png_every = 0", "[outputs].png_every = 0 is outside [1, 1000000]"},
        BadField{"png_every = 5", "png_every = 2.5", "[outputs].png_every: expected an integer, got a float"},
        BadField{"composite = true", "composite = 1", "[outputs].composite: expected true or false"},
        BadField{"composite = true", "composite = true\ndevice = \"/dev/dri/card0\"", "[outputs].device: only with backend = \"kms\""},
        BadField{"composite = true", "composite = true\ncolour = 1", "[outputs].colour: unknown field (known: backend, device"},
        BadField{R"(source = "ideal")", R"(source = "missing.mpcdi")", "[calibration].source: '"},
        BadField{R"(source = "ideal")", R"(source = "screen.mpcdi")", "[calibration].projectors: only with source = \"ideal\""},
        BadField{"projectors = 3", "projectors = 0", "[calibration].projectors = 0 is outside [1, 64]"},
        BadField{"projectors = 3", "projectors = 65", "[calibration].projectors = 65 is outside [1, 64]"},
        BadField{"overlap = 0.2", "overlap = 0.5", "[calibration].overlap = 0.5 is outside [0, 0.5)"},
        BadField{"overlap = 0.2", "overlap = -0.1", "[calibration].overlap = -0.1 is outside"},
        BadField{R"(output = "320x240")", R"(output = "320 x 240")", "[calibration].output: '320 x 240' is not WIDTHxHEIGHT"},
        BadField{"gamma = 2.4", "gamma = 0", "[calibration].gamma = 0 is outside (0, 10]"},
        BadField{R"(content = "480x270")", R"(content = "8x8")", "[quality].content = '8x8' is outside [16, 16384]"},
        BadField{"spp = 2", "spp = 0", "[quality].spp = 0 is outside [1, 4096]"},
        BadField{"spp = 2", "spp = 1.5", "[quality].spp: expected an integer, got a float"},
        BadField{"jpeg_quality = 90", "jpeg_quality = 101", "[quality].jpeg_quality = 101 is outside [1, 100]"},
        BadField{"bounces = 1", "bounces = 65", "[quality].bounces = 65 is outside [0, 64]"},
        BadField{"ao_samples = 4", "ao_samples = -1", "[quality].ao_samples = -1 is outside [0, 1024]"},
        BadField{"area_light_samples = 2", "area_light_samples = 0", "[quality].area_light_samples = 0 is outside [1, 1024]"},
        BadField{"radius_m = 3.5", "radius_m = 0", "[screen].radius_m = 0 is outside (0, 1000] m"},
        BadField{"arc_deg = 160", "arc_deg = 400", "[screen].arc_deg = 400 is outside (0, 360] degrees"},
        BadField{"bottom_m = 0.1", "bottom_m = inf", "[screen].bottom_m = inf is outside"},
        BadField{"top_m = 2.9", "top_m = 0.1", "[screen].top_m = 0.1 must be above [screen].bottom_m = 0.1"},
        BadField{R"(path = "orbit")", R"(path = "nowhere.json")", "[navigation].path: '"},
        BadField{R"(path = "orbit")", R"(path = "")", "[navigation].path: empty"},
        BadField{"path_frames = 120", "path_frames = 1", "[navigation].path_frames = 1 is outside [2, 1000000]"},
        BadField{"start = [0.0, 0.0, 4.0]", "start = [0.0, 4.0]", "[navigation].start: expected [x, y, z]"},
        BadField{"start = [0.0, 0.0, 4.0]", "start = [0.0, \"a\", 4.0]", "[navigation].start[1]: expected a number"},
        BadField{"start = [0.0, 0.0, 4.0]", "start = [0.0, 0.0, 1e12]", "[navigation].start[2] = 1000000000000 is outside"},
        BadField{"start_yaw_deg = 10", "start_yaw_deg = 4000", "[navigation].start_yaw_deg = 4000 is outside [-3600, 3600]"},
        BadField{"eye_height_m = 1.5", "eye_height_m = 0", "[navigation].eye_height_m = 0 is outside (0, 100] m"},
        BadField{"log_period_s = 2.5", "log_period_s = 0", "[stats].log_period_s = 0 is outside [0.1, 86400] s"},
        BadField{R"(file = "out/stats.json")", "file = 3", "[stats].file: expected a string"},
        BadField{"[display]", "[displays]", "[displays]: unknown section (known: farm, display"},
        BadField{"[display]\nrate_hz = 25", "[display.rate]\nhz = 25", "[display].rate: unknown field (known: rate_hz)"},
        BadField{"rate_hz = 25", "rate_hz = = 25", "not valid TOML"}));

TEST_F(KioskConfigTest, MessagesCarryTheLineOfTheOffendingValue) {
    const std::string text = good();
    const std::string message = error_of(replace(text, "spp = 2", "spp = 0"));
    const auto line = 1 + std::count(text.begin(), text.begin() + static_cast<long>(text.find("spp = 2")), '\n');
    EXPECT_NE(message.find(name().string() + ":" + std::to_string(line) + ": [quality].spp"), std::string::npos) << message;
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
    std::ifstream in(fs::path(MOGAO_SOURCE_DIR) / "kiosk/kiosk.example.toml");
    ASSERT_TRUE(in) << "kiosk/kiosk.example.toml not found";
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string prefix = "/etc/mogao/";
    for (auto at = text.find(prefix); at != std::string::npos; at = text.find(prefix, at)) {
        text.replace(at, prefix.size(), (dir_ / "etc").string() + "/");
    }
    fs::create_directories(dir_ / "etc/pki");
    for (const char* f : {"etc/pki/ca.pem", "etc/pki/appliance-museum-1.pem", "etc/pki/appliance-museum-1.key", "etc/screen.mpcdi"}) {
        std::ofstream(dir_ / f) << "x";
    }
    const KioskConfig c = parse(text);
    EXPECT_EQ(c.outputs.backend, OutputKind::kms);
    EXPECT_EQ(c.calibration.mpcdi, dir_ / "etc/screen.mpcdi");
    EXPECT_EQ(c.navigation.path, "walk");
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
