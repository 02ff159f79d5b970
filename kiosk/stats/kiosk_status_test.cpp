// SPDX-License-Identifier: Apache-2.0
// The status file's JSON (kiosk/stats/kiosk_status.h) and its atomic write.
#include "kiosk/stats/kiosk_status.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

namespace mogao {
namespace {

namespace fs = std::filesystem;

TEST(KioskStatus, UtcTextIsIso8601Seconds) {
    EXPECT_EQ(utc_text(0), "1970-01-01T00:00:00Z");
    EXPECT_EQ(utc_text(1'795'869'005'123'456'789), "2026-11-28T12:30:05Z");
}

TEST(KioskStatus, JsonHoldsConnectionFramesCalibrationAndSelfcalOff) {
    KioskStatus s;
    s.written_ns = 1'000'000'000;
    s.state = "showing";
    s.endpoint = "[::1]:7443";
    s.connected = true;
    s.frames_shown = 42;
    s.showing_request = 57;
    s.calibration.source = "/etc/mogao/screen.mpcdi";
    s.calibration.loaded_ns = 2'000'000'000;
    s.calibration.refused = 1;
    s.calibration.last_error = "/etc/mogao/screen.mpcdi: not a zip archive";
    s.calibration.last_error_ns = 3'000'000'000;
    const nlohmann::json j = kiosk_status_json(s);
    EXPECT_EQ(j["state"], "showing");
    EXPECT_EQ(j["farm"]["connected"], true);
    EXPECT_EQ(j["farm"]["endpoint"], "[::1]:7443");
    EXPECT_EQ(j["frames_shown"], 42);
    EXPECT_EQ(j["showing_request"], 57);
    EXPECT_EQ(j["calibration"]["source"], "/etc/mogao/screen.mpcdi");
    EXPECT_EQ(j["calibration"]["loaded_utc"], "1970-01-01T00:00:02Z");
    EXPECT_EQ(j["calibration"]["refused"], 1);
    EXPECT_EQ(j["calibration"]["last_error"], s.calibration.last_error);
    EXPECT_EQ(j["calibration"]["last_error_ns"], 3'000'000'000);
    EXPECT_EQ(j["selfcal"]["enabled"], false);
    EXPECT_FALSE(j["selfcal"].contains("state"));
    EXPECT_TRUE(j["last_error"].is_null());  // none since start
}

TEST(KioskStatus, JsonHoldsTheFrameRateAndTheLastError) {
    KioskStatus s;
    s.fps = 14.5;
    s.latency_mean_ms = 96.5;
    s.latency_p95_ms = 180.25;
    s.last_error = "frame dropped (3 so far): corrupt JPEG";
    s.last_error_ns = 4'000'000'000;
    const nlohmann::json j = kiosk_status_json(s);
    EXPECT_DOUBLE_EQ(j["fps"].get<double>(), 14.5);
    EXPECT_DOUBLE_EQ(j["latency_mean_ms"].get<double>(), 96.5);
    EXPECT_DOUBLE_EQ(j["latency_p95_ms"].get<double>(), 180.25);
    EXPECT_EQ(j["last_error"]["what"], s.last_error);
    EXPECT_EQ(j["last_error"]["ns"], 4'000'000'000);
    EXPECT_EQ(j["last_error"]["utc"], "1970-01-01T00:00:04Z");
}

TEST(KioskStatus, JsonHoldsTheCertificatesNotAfterInSecondsAndTheirDaysLeft) {
    KioskStatus s;
    s.written_ns = 1'800'000'000LL * 1'000'000'000;
    s.certificates = {{"ca", "mogao farm CA", 1'800'000'000 + 31 * 86'400},
                      {"appliance", "museum-1", 1'800'000'000 + 29 * 86'400 + 5}};
    nlohmann::json j = kiosk_status_json(s);
    ASSERT_EQ(j["certificates"].size(), 2u);
    EXPECT_EQ(j["certificates"][0]["role"], "ca");
    EXPECT_EQ(j["certificates"][0]["name"], "mogao farm CA");
    EXPECT_EQ(j["certificates"][0]["not_after_s"], 1'800'000'000 + 31 * 86'400);
    EXPECT_EQ(j["certificates"][0]["not_after_utc"], "2027-02-15T08:00:00Z");
    EXPECT_EQ(j["certificates"][0]["days_left"], 31);
    EXPECT_EQ(j["certificates"][0]["expires_soon"], false);
    EXPECT_EQ(j["certificates"][1]["days_left"], 29);
    EXPECT_EQ(j["certificates"][1]["expires_soon"], true);
    s.certificate_warning_days = 0;  // no warning period: only an expired one is flagged
    s.certificates[0].not_after_s = 1'800'000'000 - 1;
    j = kiosk_status_json(s);
    EXPECT_EQ(j["certificates"][0]["days_left"], -1);
    EXPECT_EQ(j["certificates"][0]["expires_soon"], true);
    EXPECT_EQ(j["certificates"][1]["expires_soon"], false);
    EXPECT_TRUE(kiosk_status_json(KioskStatus{})["certificates"].empty());
}

TEST(KioskStatus, JsonHoldsTheSelfcalStateAndProjectors) {
    KioskStatus s;
    selfcal::SelfcalStatus sc;
    sc.state = selfcal::SelfcalState::drift_detected;
    sc.t_s = 12.5;
    sc.projectors.push_back({"proj1", 212, true, 1.7, 0.9, 0.0});
    s.selfcal = sc;
    const nlohmann::json j = kiosk_status_json(s);
    EXPECT_EQ(j["selfcal"]["enabled"], true);
    EXPECT_EQ(j["selfcal"]["state"], "drift_detected");
    EXPECT_DOUBLE_EQ(j["selfcal"]["t_s"].get<double>(), 12.5);
    ASSERT_EQ(j["selfcal"]["projectors"].size(), 1u);
    EXPECT_EQ(j["selfcal"]["projectors"][0]["id"], "proj1");
    EXPECT_DOUBLE_EQ(j["selfcal"]["projectors"][0]["drift_px"].get<double>(), 1.7);
    EXPECT_FALSE(j["selfcal"]["line"].get<std::string>().empty());
    EXPECT_FALSE(j["calibration"].contains("last_error_ns")) << "no error: no error time";
}

TEST(KioskStatus, WriteReplacesTheFileWholeAndNamesAMissingFolder) {
    const fs::path dir = fs::temp_directory_path() / ("mogao-kiosk-status-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    KioskStatus s;
    s.state = "connecting";
    write_kiosk_status(dir / "status.json", s);
    s.state = "showing";
    s.frames_shown = 3;
    write_kiosk_status(dir / "status.json", s);
    std::ifstream in(dir / "status.json");
    const nlohmann::json j = nlohmann::json::parse(in);
    EXPECT_EQ(j["state"], "showing");
    EXPECT_EQ(j["frames_shown"], 3);
    std::size_t files = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++files;
    EXPECT_EQ(files, 1u) << "a temporary file was left behind";
    try {
        write_kiosk_status(dir / "missing" / "status.json", s);
        FAIL() << "a missing folder was not reported";
    } catch (const std::exception& e) {
        EXPECT_NE(std::string(e.what()).find("missing"), std::string::npos) << e.what();
    }
    fs::remove_all(dir);
}

}  // namespace
}  // namespace mogao
