// SPDX-License-Identifier: Apache-2.0
#include "kiosk/stats/kiosk_metrics.h"

#include <cstdlib>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include <gtest/gtest.h>

#include "kiosk/stats/kiosk_stats.h"
#include "tests/support/scratch_dir.h"

namespace mogao {
namespace {

// Sample lines "name{labels} value" -> value.
std::map<std::string, std::string> samples(const std::string& text) {
    std::map<std::string, std::string> out;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) {
        if (line.empty() || line[0] == '#') continue;
        const auto space = line.rfind(' ');
        out[line.substr(0, space)] = line.substr(space + 1);
    }
    return out;
}

KioskStatus showing_status() {
    KioskStatus s;
    s.written_ns = 1'700'000'100'000'000'000;
    s.uptime_s = 100.0;
    s.state = "showing";
    s.connected = true;
    s.frames_shown = 3;
    s.farm_silent_s = 0.25;
    s.calibration.loaded_ns = 1'700'000'050'000'000'000;
    s.calibration.swaps = 5;
    s.calibration.refused = 1;
    selfcal::SelfcalStatus sc;
    sc.state = selfcal::SelfcalState::drift_detected;
    sc.projectors = {{"proj0", 200, true, 0.4, 0.01, 0.2}, {"proj1", 180, true, 1.5, 0.03, 0.9}};
    s.selfcal = sc;
    s.certificates = {{"ca", "mogao farm CA", 2'000'000'000}, {"appliance", "kiosk-1", 1'790'000'000}};
    return s;
}

// Three frames presented 30 ms, 90 ms and 1.5 s after their requests, through the real KioskStats.
KioskStats three_frames() {
    KioskStats stats;
    const std::int64_t ms = 1'000'000;
    for (const auto& [id, latency_ms] : {std::pair{1, 30}, {2, 90}, {3, 1500}}) {
        PresentedFrame f;
        f.request_id = static_cast<std::uint64_t>(id);
        f.request_ns = id * 1000 * ms;
        f.receive_ns = f.request_ns + ms;
        f.presented_ns = f.request_ns + latency_ms * ms;
        stats.presented(f);
    }
    return stats;
}

// With MOGAO_METRICS_SAMPLE_DIR set, the text is also left there for tests/monitoring_check.sh
// (promtool check metrics, and every name the alert rules and dashboard use).
void leave_sample(const std::string& text) {
    const char* dir = std::getenv("MOGAO_METRICS_SAMPLE_DIR");
    if (dir == nullptr || *dir == 0) return;
    std::ofstream(std::filesystem::path(dir) / "mogao-kiosk.prom") << text;
}

TEST(KioskMetrics, EveryFamilyWithItsValueFromTheStatusAndTheCounters) {
    const KioskStats stats = three_frames();
    KioskCounters c;
    c.motion_to_photon = &stats.motion_to_photon();
    c.link.sessions_opened = 2;
    c.link.attempts_failed = 4;
    c.link.frames_received = 9;
    c.link.bytes_received = 123456;
    c.frames_dropped = 1;
    c.selfcal_corrections = 2;
    c.selfcal_swaps = 3;
    c.version = "1.2.3";
    const std::string text = kiosk_metrics_text(showing_status(), c);
    leave_sample(text);
    const std::regex line(R"(^(# (HELP|TYPE) mogao_kiosk_[a-z_]+ .+|)"
                          R"(mogao_kiosk_[a-z_]+(\{[a-z_]+="[^"]*"(,[a-z_]+="[^"]*")*\})? -?[0-9.e+]+)$)");
    std::istringstream in(text);
    for (std::string l; std::getline(in, l);) EXPECT_TRUE(std::regex_match(l, line)) << l;
    const auto s = samples(text);
    EXPECT_EQ(s.at("mogao_kiosk_up"), "1");
    EXPECT_EQ(s.at("mogao_kiosk_last_update_timestamp_seconds"), "1700000100");
    EXPECT_EQ(s.at("mogao_kiosk_start_time_seconds"), "1700000000");
    EXPECT_EQ(s.at("mogao_kiosk_build_info{version=\"1.2.3\"}"), "1");
    EXPECT_EQ(s.at("mogao_kiosk_state{state=\"showing\"}"), "1");
    EXPECT_EQ(s.at("mogao_kiosk_state{state=\"disconnected\"}"), "0");
    EXPECT_EQ(s.at("mogao_kiosk_link_connected"), "1");
    EXPECT_EQ(s.at("mogao_kiosk_link_connect_failures_total"), "4");
    EXPECT_EQ(s.at("mogao_kiosk_link_jpeg_bytes_received_total"), "123456");
    EXPECT_EQ(s.at("mogao_kiosk_frames_shown_total"), "3");
    EXPECT_EQ(s.at("mogao_kiosk_frames_dropped_total"), "1");
    // 30 ms, 90 ms, 1.5 s counted by hand into the buckets.
    EXPECT_EQ(s.at("mogao_kiosk_motion_to_photon_seconds_bucket{le=\"0.02\"}"), "0");
    EXPECT_EQ(s.at("mogao_kiosk_motion_to_photon_seconds_bucket{le=\"0.035\"}"), "1");
    EXPECT_EQ(s.at("mogao_kiosk_motion_to_photon_seconds_bucket{le=\"0.1\"}"), "2");
    EXPECT_EQ(s.at("mogao_kiosk_motion_to_photon_seconds_bucket{le=\"1\"}"), "2");
    EXPECT_EQ(s.at("mogao_kiosk_motion_to_photon_seconds_bucket{le=\"+Inf\"}"), "3");
    EXPECT_DOUBLE_EQ(std::stod(s.at("mogao_kiosk_motion_to_photon_seconds_sum")), 1.62);
    EXPECT_EQ(s.at("mogao_kiosk_calibration_swaps_total{source=\"file\"}"), "2");
    EXPECT_EQ(s.at("mogao_kiosk_calibration_swaps_total{source=\"selfcal\"}"), "3");
    EXPECT_EQ(s.at("mogao_kiosk_calibration_refused_total"), "1");
    EXPECT_EQ(s.at("mogao_kiosk_calibration_loaded_timestamp_seconds"), "1700000050");
    EXPECT_EQ(s.at("mogao_kiosk_selfcal_state{state=\"drift_detected\"}"), "1");
    EXPECT_EQ(s.at("mogao_kiosk_selfcal_state{state=\"calibrated\"}"), "0");
    EXPECT_EQ(s.at("mogao_kiosk_selfcal_corrections_total"), "2");
    EXPECT_EQ(s.at("mogao_kiosk_selfcal_drift_pixels{projector=\"proj1\"}"), "1.5");
    EXPECT_EQ(s.at("mogao_kiosk_certificate_not_after_seconds{role=\"appliance\",name=\"kiosk-1\"}"), "1790000000");
    EXPECT_NE(text.find("# TYPE mogao_kiosk_motion_to_photon_seconds histogram"), std::string::npos);
    EXPECT_NE(text.find("# TYPE mogao_kiosk_frames_shown_total counter"), std::string::npos);
}

TEST(KioskMetrics, StoppedIsDownAndNoSelfcalFamiliesWithoutSelfcal) {
    KioskStatus s = showing_status();
    s.state = "stopped";
    s.selfcal.reset();
    const std::string text = kiosk_metrics_text(s, KioskCounters{});
    const auto m = samples(text);
    EXPECT_EQ(m.at("mogao_kiosk_up"), "0");
    EXPECT_EQ(m.at("mogao_kiosk_state{state=\"stopped\"}"), "1");
    EXPECT_EQ(text.find("selfcal_state"), std::string::npos);
    EXPECT_EQ(text.find("motion_to_photon"), std::string::npos);  // no histogram given
}

TEST(KioskMetrics, WrittenToTheFileNamedAndRefusedForAMissingFolder) {
    const testing::ScratchDir dir("kiosk-metrics");
    write_kiosk_metrics(dir.path() / "kiosk.prom", showing_status(), KioskCounters{});
    std::ifstream in(dir.path() / "kiosk.prom");
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(samples(text).at("mogao_kiosk_frames_shown_total"), "3");
    try {
        write_kiosk_metrics(dir.path() / "no-such-folder" / "kiosk.prom", showing_status(), KioskCounters{});
        ADD_FAILURE() << "no error for a missing folder";
    } catch (const std::system_error& e) {
        EXPECT_NE(std::string(e.what()).find("no-such-folder/kiosk.prom"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace mogao
