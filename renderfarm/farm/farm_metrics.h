// SPDX-License-Identifier: Apache-2.0
// What a render-farm operator sees: the serving farm's figures in the Prometheus text exposition
// format (common/prometheus_text.h), written atomically into node_exporter's textfile collector
// folder (Debian's prometheus-node-exporter reads /var/lib/prometheus/node-exporter/*.prom), so no
// HTTP server of our own is needed. Named by Prometheus' conventions: base units (seconds, bytes),
// counters end in _total, distributions are histograms. docs/monitoring.md lists every series with
// its type, labels and unit, and the alert rules that read them.
//
// Metrics (all prefixed mogao_farm_):
//   up (gauge: 1 while serving, 0 once stopped)         last_update_timestamp_seconds (Unix time of this file)
//   build_info{version} 1                                render_ranks
//   frames_total, frame_seconds (histogram: the frame's time on the admin: render, composite, accumulate)
//   render_phase_seconds (histogram), balance_efficiency (histogram: mean / max rank time per frame)
//   rays_total, rank_render_seconds_total{rank="N"} (MPI rank), frames_cut_total (frame budget)
//   appliance_frames_total{appliance}, appliance_frame_seconds_total{appliance}: by the appliance's
//     certificate common name, at most kMaxApplianceLabels names (the first seen), the rest as
//     "other" (and frames of a session already closed as "unknown"), so that the series stay bounded
//   last_frame_timestamp_seconds (Unix time)
//   sessions_active, sessions_opened_total, sessions_refused_total, sessions_revoked_total
//   connections_open, connections_unauthenticated, connections_accepted_total,
//   connections_refused_total{cap="max_connections|max_unauthenticated|max_unauthenticated_per_address"},
//   connections_aged_out_total (renderfarm/link/connection_guard.h)
//   requests_received_total, requests_invalid_total, requests_dropped_total,
//   requests_superseded_total, requests_degraded_total (request_policy.h), render_failures_total
//   frames_sent_total, jpeg_bytes_sent_total
//   certificate_not_after_seconds{role="ca|farm",name="<subject CN>"} (Unix time, each certificate
//   the farm serves with: LinkServerStats::certificates, renderfarm/link/cert_expiry.h)
//   crl_next_update_seconds (Unix time; only with a revocation list that has a nextUpdate)
//
// Liveness: node_exporter serves the file's last contents for as long as it exists, so a farm that
// died without rewriting it (SIGKILL from mpirun, the OOM killer, a crash) would still read up 1.
// Hence last_update_timestamp_seconds, rewritten with every file (about once a second): an alert on
// `time() - mogao_farm_last_update_timestamp_seconds` sees a farm that stopped writing, whatever
// killed it. FarmMetricsFile writes up 0 on every way out of serving it can see: SIGTERM/SIGINT (from
// the signal handler), the serve loop's end, an exception leaving it (destructor), and
// std::terminate (a handler installed while it lives).
// Errors: FarmMetrics::write throws std::system_error naming the file (common/file_io.h);
// FarmMetricsFile logs a failure once per kind of error and never stops serving.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "common/prometheus_text.h"
#include "renderfarm/farm/frame_stats.h"
#include "renderfarm/link/link_server.h"

namespace mogao {

struct FarmCounters {
    bool up = true;  // false in the file written when the farm stops
    LinkServerStats link;
    std::uint64_t superseded = 0;  // requests replaced in the farm's queue
    std::uint64_t degraded = 0;    // requests degraded by the request policy
    int render_ranks = 1;
};

class FarmMetrics {
public:
    // Distinct appliance label values kept; later appliances share "other".
    static constexpr std::size_t kMaxApplianceLabels = 32;

    // `version`: the build_info label (the project's version, common/program_cli.h).
    explicit FarmMetrics(std::string version);

    // One rendered frame (LiveFrame::stats), its time on the admin, when it was finished (Unix
    // seconds), and the appliance it was for (its certificate's common name; empty: unknown).
    void observe_frame(const FrameStats& stats, double frame_seconds, double unix_seconds,
                       const std::string& appliance = {});

    // The exposition text for the frames seen so far and `counters`, written at `now_unix_seconds`.
    [[nodiscard]] std::string text(const FarmCounters& counters, double now_unix_seconds) const;

    // text() written atomically to `file` (prometheus::write_textfile: a reader never sees half a
    // file, and node_exporter's user may read it).
    void write(const std::filesystem::path& file, const FarmCounters& counters, double now_unix_seconds) const;

private:
    struct PerAppliance {
        std::uint64_t frames = 0;
        double seconds = 0.0;
    };
    void frame_families(prometheus::TextWriter& w) const;
    [[nodiscard]] const std::string& appliance_label(const std::string& appliance);

    std::string version_;
    std::uint64_t frames_ = 0;
    std::uint64_t frames_cut_ = 0;
    std::uint64_t rays_ = 0;
    prometheus::Histogram frame_seconds_;
    prometheus::Histogram render_phase_seconds_;
    prometheus::Histogram balance_efficiency_;
    std::vector<double> rank_render_seconds_;  // index 0 = MPI rank 1
    std::map<std::string, PerAppliance> appliances_;
    double last_unix_ = 0.0;
};

// The metrics file of a serving farm (ServeOptions::metrics_file): update() rewrites it; a stop
// signal (on_stop_signal, from the handler: systemd and mpirun may SIGKILL the admin before its loop
// sees the signal), the destructor and std::terminate rewrite it with up 0 (see "Liveness" above).
// One at a time per process (the handlers serve the latest).
class FarmMetricsFile {
public:
    explicit FarmMetricsFile(std::filesystem::path file);  // empty: writes nothing
    ~FarmMetricsFile();
    FarmMetricsFile(const FarmMetricsFile&) = delete;
    FarmMetricsFile& operator=(const FarmMetricsFile&) = delete;

    // Writes metrics and `counters` (up as counters.up, 0 after a stop signal) now, and keeps the
    // up-0 text ready for the handlers.
    void update(const FarmMetrics& metrics, const FarmCounters& counters);

    // Async-signal-safe: the current file's last update with up 0. For SIGTERM/SIGINT handlers.
    static void on_stop_signal() noexcept;

private:
    static void on_terminate();
    // The last update's counts with up 0, unless written already (or `again`); false when it could not
    // be written (`*error`: its errno, when given).
    [[nodiscard]] bool write_down(bool again = false, int* error = nullptr) noexcept;

    std::filesystem::path file_;
    std::string down_tmp_;  // the temporary for write_down, built before any signal
    std::string up_tmp_;    // update's own, so that a handler never writes into it
    std::string last_error_;
    std::string down_text_;  // the last update's text with up 0
    std::atomic_flag busy_;  // held while down_text_ changes or is written
    bool wrote_down_ = false;
    std::atomic<bool> stopping_{false};
    std::terminate_handler previous_ = nullptr;
};

}  // namespace mogao
