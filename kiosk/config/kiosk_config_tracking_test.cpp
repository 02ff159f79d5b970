// SPDX-License-Identifier: Apache-2.0
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "kiosk/config/config_overrides.h"
#include "kiosk/config/kiosk_config.h"
#include "kiosk/config/kiosk_config_test_support.h"

namespace mogao {
namespace {

namespace fs = std::filesystem;
using kiosk_config_test::BadField;
using kiosk_config_test::KioskConfigTest;
using kiosk_config_test::read_source_file;
using kiosk_config_test::replace;

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

}  // namespace
}  // namespace mogao
