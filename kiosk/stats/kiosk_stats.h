// SPDX-License-Identifier: Apache-2.0
// KioskStats: what the kiosk measures per displayed frame, its periodic stderr summary and the
// statistics JSON written at exit.
//
// Per frame (times are CLOCK_REALTIME nanoseconds of the appliance, common/link_types.h):
//   motion-to-photon = presented_ns - request_ns: the view request was stamped (pose sampled) ->
//                      every output presented the frame in one round (headless: the round's
//                      read-backs completed; KMS: the latest page-flip event timestamp of the
//                      round's atomic commit, the kernel's time scan-out of the frame began)
//   link             = receive_ns - request_ns (request upstream + render + encode + downstream)
//   kiosk            = presented_ns - receive_ns (slot hand-over + decode + warp/blend + flip)
//   bytes            = JPEG bytes of the frame
// Rates over a sliding window of the last `window` presented frames: fps = (n - 1) / span of their
// presented times, bandwidth = bytes of all but the first / span (the first frame's bytes arrived
// before the span began). Totals cover the whole run in fixed memory: means, least and greatest
// from running sums; percentiles exact while every frame is kept, else from a QuantileSketch (within
// 0.5 % of a value of that rank; quantile_sketch.h). The per-frame list in the JSON keeps the first
// `frames_kept` frames (allocated once); an optional FrameLog (frame_log.h) appends every frame's
// record to a file instead, for runs of any length. Events are kept up to kMaxEvents (then counted).
//
// Not thread-safe: the event loop owns it.
//
// Also here: the statistics JSON's other sections (link, navigation, run), built from the parts'
// counters at exit (docs/kiosk.md lists the fields; tests and the live tour read them).
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/pixel_rect.h"
#include "common/prometheus_text.h"
#include "common/view_request.h"
#include "kiosk/stats/frame_log.h"
#include "kiosk/stats/quantile_sketch.h"

namespace mogao {

struct LinkClientStats;   // renderfarm/link/link_client.h
struct TrackingCounters;  // kiosk/navigation/tracking_thread.h

struct PresentedFrame {
    std::uint64_t request_id = 0;
    std::uint64_t link_frame_id = 0;
    std::size_t jpeg_bytes = 0;
    std::int64_t request_ns = 0;
    std::int64_t receive_ns = 0;
    std::int64_t presented_ns = 0;
    double decode_ms = 0;
    std::uint64_t display_round = 0;   // the kiosk's display round that first showed it
    ImageSize served;                  // the frame's pixels as the farm rendered them (its JPEG's size)
    std::uint32_t served_spp = 0;      // its samples per pixel as served (0: the farm did not say)
    std::uint32_t served_bounces = 0;  // its indirect bounces as served
};

struct StatsSummary {
    std::uint64_t frames = 0;
    double fps = 0;
    double latency_mean_ms = 0;  // motion-to-photon
    double latency_p50_ms = 0;
    double latency_p95_ms = 0;
    double latency_max_ms = 0;
    double link_mean_ms = 0;   // request -> receive
    double kiosk_mean_ms = 0;  // receive -> presented
    double decode_mean_ms = 0;
    double bytes_per_frame = 0;
    double bandwidth_bytes_per_s = 0;
};

class KioskStats {
public:
    static constexpr std::size_t kDefaultWindow = 120;
    static constexpr std::size_t kDefaultFramesKept = 4096;  // [stats].frames_kept's default
    static constexpr std::size_t kMaxEvents = 1000;

    explicit KioskStats(std::size_t window = kDefaultWindow, std::size_t frames_kept = kDefaultFramesKept);

    // Appends every frame presented from now on to `path` (FrameLog). Throws std::system_error
    // naming the path.
    void open_frame_log(const std::filesystem::path& path);

    void presented(const PresentedFrame& frame);
    void rejected() { ++rejected_; }                       // a frame failed to decode (last good kept)
    void superseded(std::uint64_t n) { superseded_ = n; }  // frames replaced in the slot (running total)
    void display_round() { ++rounds_; }                    // one present on every ready output
    // A link state change or other notable event, kept in order with its time and display round.
    void event(std::int64_t realtime_ns, std::string what, std::uint64_t last_request_id);

    [[nodiscard]] std::uint64_t frames() const { return frames_; }
    [[nodiscard]] std::uint64_t rounds() const { return rounds_; }
    [[nodiscard]] StatsSummary window_summary() const;  // the sliding window
    [[nodiscard]] StatsSummary total_summary() const;   // the whole run
    // Motion-to-photon of every presented frame, seconds (kiosk_metrics.h's buckets), for the metrics.
    [[nodiscard]] const prometheus::Histogram& motion_to_photon() const { return motion_to_photon_; }

    // One journald-friendly line (no timestamp): frames, fps, latency, bytes, bandwidth, counters.
    [[nodiscard]] std::string log_line() const;

    // Everything: summaries, counters, events, per-frame list. `extra` is merged at the top level.
    // When `extra` holds "content": [width, height] (run_stats_json), each frame's served scale
    // (its height over the content's: the guard band widens a request, never heightens it) is in
    // the per-frame list and its mean, least and 5th percentile in "total.served_scale". Each frame's
    // samples per pixel and bounces as served, when the farm reported them, are in the per-frame list
    // ("served_spp", "served_bounces") and their mean and least in "total.served_quality".
    [[nodiscard]] nlohmann::json to_json(const nlohmann::json& extra = nlohmann::json::object()) const;

    // Writes to_json(extra) atomically (common/file_io.h). Throws std::system_error
    // naming the path.
    void write_json(const std::filesystem::path& path, const nlohmann::json& extra = nlohmann::json::object()) const;

private:
    // Running sums over every presented frame (fixed memory).
    struct Totals {
        double latency_sum_ms = 0, latency_max_ms = 0, link_sum_ms = 0, kiosk_sum_ms = 0, decode_sum_ms = 0;
        std::int64_t first_presented_ns = 0, last_presented_ns = 0;
        std::size_t first_bytes = 0;
        double served_height_sum = 0;
        int served_height_min = 0;
        std::uint64_t quality_frames = 0;  // frames whose spp the farm reported
        double spp_sum = 0, bounce_sum = 0;
        std::uint32_t spp_min = 0, bounce_min = 0;
    };

    [[nodiscard]] static StatsSummary summarise(const std::vector<const PresentedFrame*>& frames);
    [[nodiscard]] bool every_frame_kept() const { return history_.size() == frames_; }
    void add_to_totals(const PresentedFrame& frame);
    [[nodiscard]] nlohmann::json served_scale_json(const nlohmann::json& extra) const;
    [[nodiscard]] nlohmann::json served_quality_json() const;

    std::size_t window_size_;
    std::size_t frames_kept_;
    std::deque<PresentedFrame> window_;
    std::vector<PresentedFrame> history_;  // the first frames_kept_ frames
    Totals totals_;
    QuantileSketch latency_ms_;     // motion-to-photon of every frame
    QuantileSketch served_height_;  // served height of every frame
    std::unique_ptr<FrameLog> frame_log_;
    std::uint64_t events_dropped_ = 0;
    std::uint64_t frames_ = 0;
    std::uint64_t bytes_ = 0;
    std::uint64_t rejected_ = 0;
    std::uint64_t superseded_ = 0;
    std::uint64_t rounds_ = 0;
    std::uint64_t out_of_order_ = 0;  // presented request ids not increasing (must stay 0)
    std::uint64_t last_request_id_ = 0;
    nlohmann::json events_ = nlohmann::json::array();
    prometheus::Histogram motion_to_photon_;
};

// "link": the LinkClient's counters at exit.
[[nodiscard]] nlohmann::json link_stats_json(const LinkClientStats& link);

// The tracking fields of "navigation": camera, tracking thread counters, queue and gate counts, final pose.
[[nodiscard]] nlohmann::json tracking_stats_json(const std::string& camera, const TrackingCounters& counters,
                                                 std::uint64_t samples_queued, std::uint64_t samples_dropped,
                                                 std::uint64_t samples_rejected_by_gate, const ViewerPose& final_pose);

// The run's fields beside KioskStats' own (KioskStats::write_json's `extra`).
struct RunRecord {
    std::string endpoint;
    ImageSize content;
    int jpeg_quality = 0;
    nlohmann::json navigation;  // KioskNavigation::report
    nlohmann::json link;        // link_stats_json
    int exit_code = 0;
};
[[nodiscard]] nlohmann::json run_stats_json(const RunRecord& run);

}  // namespace mogao
