// SPDX-License-Identifier: Apache-2.0
#include "kiosk/stats/kiosk_stats.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <malloc.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <system_error>

namespace mogao {
namespace {

constexpr std::int64_t kMs = 1'000'000;

// Frame k: requested at k * 40 ms, received 30 ms later, presented 50 ms after the request.
PresentedFrame frame(std::uint64_t k, std::size_t bytes = 1000) {
    PresentedFrame f;
    f.request_id = k;
    f.link_frame_id = k;
    f.jpeg_bytes = bytes;
    f.request_ns = static_cast<std::int64_t>(k) * 40 * kMs;
    f.receive_ns = f.request_ns + 30 * kMs;
    f.presented_ns = f.request_ns + 50 * kMs;
    f.decode_ms = 2.0;
    return f;
}

TEST(KioskStats, SummarisesLatencyRateAndBandwidth) {
    KioskStats stats(10);
    for (std::uint64_t k = 1; k <= 11; ++k) stats.presented(frame(k));
    const StatsSummary w = stats.window_summary();
    EXPECT_EQ(w.frames, 10u);
    EXPECT_NEAR(w.fps, 25.0, 1e-9);  // one frame per 40 ms
    EXPECT_NEAR(w.latency_mean_ms, 50.0, 1e-9);
    EXPECT_NEAR(w.latency_max_ms, 50.0, 1e-9);
    EXPECT_NEAR(w.link_mean_ms, 30.0, 1e-9);
    EXPECT_NEAR(w.kiosk_mean_ms, 20.0, 1e-9);
    EXPECT_NEAR(w.bytes_per_frame, 1000.0, 1e-9);
    EXPECT_NEAR(w.bandwidth_bytes_per_s, 25'000.0, 1e-6);  // 9 frames' bytes over 9 intervals
    EXPECT_EQ(stats.total_summary().frames, 11u);
}

TEST(KioskStats, PercentilesOverTheRun) {
    KioskStats stats;
    for (std::uint64_t k = 1; k <= 100; ++k) {
        PresentedFrame f = frame(k);
        f.presented_ns = f.request_ns + static_cast<std::int64_t>(k) * kMs;  // latency k ms
        stats.presented(f);
    }
    const StatsSummary t = stats.total_summary();
    EXPECT_NEAR(t.latency_p50_ms, 50.0, 1e-9);
    EXPECT_NEAR(t.latency_p95_ms, 95.0, 1e-9);
    EXPECT_NEAR(t.latency_max_ms, 100.0, 1e-9);
    EXPECT_NEAR(t.latency_mean_ms, 50.5, 1e-9);
}

// The served scale: each frame's height over the content's (the guard band widens the request).
TEST(KioskStats, JsonHoldsTheServedSizeAndScaleOfEveryFrame) {
    KioskStats stats;
    const int heights[4] = {270, 540, 405, 540};
    for (std::uint64_t k = 1; k <= 4; ++k) {
        PresentedFrame f = frame(k);
        f.served = {2 * heights[k - 1], heights[k - 1]};
        stats.presented(f);
    }
    const nlohmann::json j = stats.to_json({{"content", {960, 540}}});
    EXPECT_EQ(j["frames"][0]["served"], nlohmann::json({540, 270}));
    EXPECT_DOUBLE_EQ(j["frames"][0]["served_scale"].get<double>(), 0.5);
    EXPECT_DOUBLE_EQ(j["frames"][2]["served_scale"].get<double>(), 0.75);
    EXPECT_NEAR(j["total"]["served_scale"]["mean"].get<double>(), 0.8125, 1e-3);  // rounded to 3 places
    EXPECT_DOUBLE_EQ(j["total"]["served_scale"]["min"].get<double>(), 0.5);
    // Without the content's size the sizes are kept and no scale is made up.
    const nlohmann::json bare = stats.to_json();
    EXPECT_EQ(bare["frames"][1]["served"], nlohmann::json({1080, 540}));
    EXPECT_FALSE(bare["frames"][1].contains("served_scale"));
    EXPECT_TRUE(bare["total"]["served_scale"].is_null());
}

// The samples and bounces the farm served each frame with (a still view's accumulation counts every
// pass); frames from a farm that did not report them (0) are left out of the summary.
TEST(KioskStats, JsonHoldsTheServedSamplesAndBouncesOfEveryFrame) {
    KioskStats stats;
    const std::uint32_t spp[4] = {1, 0, 3, 5}, bounces[4] = {1, 0, 2, 2};
    for (std::uint64_t k = 1; k <= 4; ++k) {
        PresentedFrame f = frame(k);
        f.served_spp = spp[k - 1];
        f.served_bounces = bounces[k - 1];
        stats.presented(f);
    }
    const nlohmann::json j = stats.to_json();
    EXPECT_EQ(j["frames"][2]["served_spp"], 3);
    EXPECT_EQ(j["frames"][2]["served_bounces"], 2);
    EXPECT_FALSE(j["frames"][1].contains("served_spp")) << "not reported: no value made up";
    const nlohmann::json& q = j["total"]["served_quality"];
    EXPECT_EQ(q["frames"], 3);
    EXPECT_NEAR(q["spp"]["mean"].get<double>(), 3.0, 1e-9);
    EXPECT_EQ(q["spp"]["min"], 1);
    EXPECT_NEAR(q["bounces"]["mean"].get<double>(), 5.0 / 3.0, 1e-3);
    EXPECT_EQ(q["bounces"]["min"], 1);
    KioskStats none;
    none.presented(frame(1));
    EXPECT_TRUE(none.to_json()["total"]["served_quality"].is_null());
}

TEST(KioskStats, JsonHoldsCountersEventsAndFramesInOrder) {
    KioskStats stats;
    stats.presented(frame(1));
    stats.event(123, "disconnected", 1);
    stats.presented(frame(3, 2000));
    stats.presented(frame(2));  // out of order: must be visible in the record
    stats.rejected();
    stats.superseded(4);
    stats.display_round();
    const nlohmann::json j = stats.to_json({{"endpoint", "[::1]:1"}});
    EXPECT_EQ(j["frames_presented"], 3);
    EXPECT_EQ(j["jpeg_bytes_presented"], 4000);
    EXPECT_EQ(j["frames_rejected"], 1);
    EXPECT_EQ(j["frames_superseded"], 4);
    EXPECT_EQ(j["frames_out_of_order"], 1);
    EXPECT_EQ(j["display_rounds"], 1);
    EXPECT_EQ(j["endpoint"], "[::1]:1");
    ASSERT_EQ(j["events"].size(), 1u);
    EXPECT_EQ(j["events"][0]["event"], "disconnected");
    EXPECT_EQ(j["events"][0]["frames"], 1);
    ASSERT_EQ(j["frames"].size(), 3u);
    EXPECT_EQ(j["frames"][1]["request_id"], 3);
    EXPECT_DOUBLE_EQ(j["frames"][1]["motion_to_photon_ms"].get<double>(), 50.0);
    EXPECT_NE(stats.log_line().find("frames=3"), std::string::npos) << stats.log_line();
}

TEST(KioskStats, HistoryIsBoundedButCountersKeepCounting) {
    KioskStats stats(4, 5);
    for (std::uint64_t k = 1; k <= 20; ++k) stats.presented(frame(k));
    const nlohmann::json j = stats.to_json();
    EXPECT_EQ(j["frames"].size(), 5u);
    EXPECT_EQ(j["frames_presented"], 20);
    EXPECT_EQ(j["window"]["frames"], 4);
}

// Beyond the kept frames the totals still cover the whole run: means and the greatest exactly,
// percentiles from the sketch within its 0.5 %.
TEST(KioskStats, TotalsCoverTheWholeRunBeyondTheKeptFrames) {
    KioskStats stats(10, 50);
    std::vector<double> latency;
    for (std::uint64_t k = 1; k <= 2000; ++k) {
        PresentedFrame f = frame(k);
        const double l = 20.0 + static_cast<double>((k * 7919) % 1000) / 10.0;  // 20..119.9 ms, shuffled
        f.presented_ns = f.request_ns + static_cast<std::int64_t>(l * kMs);
        f.served = {960 - int(k % 3) * 240, 540 - int(k % 3) * 135};
        stats.presented(f);
        latency.push_back(l);
    }
    std::sort(latency.begin(), latency.end());
    const StatsSummary t = stats.total_summary();
    EXPECT_EQ(t.frames, 2000u);
    EXPECT_NEAR(t.latency_mean_ms, 69.95, 1e-6);
    EXPECT_NEAR(t.latency_max_ms, 119.9, 1e-6);
    EXPECT_NEAR(t.latency_p50_ms, latency[999], 0.005 * latency[999]);
    EXPECT_NEAR(t.latency_p95_ms, latency[1899], 0.005 * latency[1899]);
    EXPECT_NEAR(t.fps, 25.0, 0.1);
    const nlohmann::json j = stats.to_json({{"content", {960, 540}}});
    EXPECT_EQ(j["frames"].size(), 50u);
    EXPECT_EQ(j["total"]["percentiles"], "sketch (within 0.5 %)");
    EXPECT_NEAR(j["total"]["served_scale"]["mean"].get<double>(), 0.75, 0.001);
    EXPECT_NEAR(j["total"]["served_scale"]["min"].get<double>(), 0.5, 1e-9);
    EXPECT_NEAR(j["total"]["served_scale"]["p05"].get<double>(), 0.5, 0.5 * 0.005);
}

// The kiosk plays for years: after its kept frames are filled, presenting more allocates nothing
// that stays (a per-frame list that grew with the run cost 1.5 MiB/h in the 2-hour soak).
TEST(KioskStats, MemoryStaysFixedWhileTheWallPlays) {
    KioskStats stats;
    stats.event(1, "connected", 0);
    std::uint64_t k = 1;
    for (; k <= KioskStats::kDefaultFramesKept + 500; ++k) stats.presented(frame(k));
    const auto in_use = [] {
        const struct mallinfo2 m = mallinfo2();
        return m.uordblks + m.hblkhd;
    };
    const std::size_t before = in_use();
    for (; k <= 100'000; ++k) stats.presented(frame(k));
    const std::size_t after = in_use();
    EXPECT_LT(after, before + 16 * 1024) << "bytes in use grew from " << before << " to " << after;
    EXPECT_EQ(stats.total_summary().frames, 100'000u);
}

TEST(KioskStats, EventsAreKeptUpToTheirLimitThenCounted) {
    KioskStats stats;
    for (std::size_t i = 0; i < KioskStats::kMaxEvents + 7; ++i) stats.event(std::int64_t(i), "reconnected", i);
    const nlohmann::json j = stats.to_json();
    EXPECT_EQ(j["events"].size(), KioskStats::kMaxEvents);
    EXPECT_EQ(j["events_dropped"], 7);
}

TEST(KioskStats, FrameLogHoldsEveryFrameAsAJsonLine) {
    const auto path =
        std::filesystem::temp_directory_path() / ("mogao-frame-log-" + std::to_string(::getpid()) + ".jsonl");
    KioskStats stats(10, 2);
    stats.open_frame_log(path);
    for (std::uint64_t k = 1; k <= 5; ++k) stats.presented(frame(k));
    std::ifstream in(path);
    std::string line;
    std::uint64_t k = 0;
    while (std::getline(in, line)) {
        const nlohmann::json j = nlohmann::json::parse(line);
        EXPECT_EQ(j["request_id"], ++k);
        EXPECT_DOUBLE_EQ(j["motion_to_photon_ms"].get<double>(), 50.0);
    }
    EXPECT_EQ(k, 5u);
    const nlohmann::json j = stats.to_json();
    EXPECT_EQ(j["frames"].size(), 2u);
    EXPECT_EQ(j["frame_log"]["lines"], 5);
    EXPECT_FALSE(j["frame_log"].contains("error"));
    std::filesystem::remove(path);
    try {
        stats.open_frame_log("/nonexistent-dir/frames.jsonl");
        ADD_FAILURE() << "no error for a folder that does not exist";
    } catch (const std::system_error& e) {
        EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/frames.jsonl"), std::string::npos) << e.what();
    }
}

TEST(QuantileSketch, AnswersWithinItsRelativeAccuracy) {
    QuantileSketch sketch(0.01, 0.1, 1e5);
    std::vector<double> values;
    for (int i = 1; i <= 5000; ++i) values.push_back(0.5 * std::pow(1.0023, i));  // 0.5 .. ~49000
    for (std::size_t i = 0; i < values.size(); ++i) sketch.add(values[(i * 2654435761U) % values.size()]);
    for (const double q : {0.0, 0.01, 0.05, 0.5, 0.95, 0.99, 1.0}) {
        const auto rank = std::max<std::size_t>(1, std::size_t(std::ceil(q * 5000)));
        const double exact = values[rank - 1];
        EXPECT_NEAR(sketch.quantile(q), exact, 0.01 * exact) << "q " << q;
    }
    EXPECT_EQ(sketch.count(), 5000u);
    sketch.add(0);
    sketch.add(-3);
    EXPECT_EQ(sketch.quantile(0), 0);
    sketch.add(1e9);  // beyond the range: answered as its end
    EXPECT_NEAR(sketch.quantile(1), 1e5, 0.01 * 1e5);
    EXPECT_EQ(QuantileSketch(0.01, 1, 2).quantile(0.5), 0) << "empty";
    EXPECT_THROW(QuantileSketch(0, 1, 2), std::invalid_argument);
    EXPECT_THROW(QuantileSketch(0.6, 1, 2), std::invalid_argument);
    EXPECT_THROW(QuantileSketch(0.01, 0, 2), std::invalid_argument);
    EXPECT_THROW(QuantileSketch(0.01, 3, 2), std::invalid_argument);
}

TEST(KioskStats, WritesTheJsonFile) {
    const auto path =
        std::filesystem::temp_directory_path() / ("mogao-kiosk-stats-" + std::to_string(::getpid()) + ".json");
    KioskStats stats;
    stats.presented(frame(1));
    stats.write_json(path);
    std::ifstream in(path);
    const nlohmann::json j = nlohmann::json::parse(in);
    EXPECT_EQ(j["frames_presented"], 1);
    std::filesystem::remove(path);
    EXPECT_THROW(stats.write_json("/nonexistent-dir/stats.json"), std::exception);
}

}  // namespace
}  // namespace mogao
