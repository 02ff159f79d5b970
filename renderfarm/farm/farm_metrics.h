// SPDX-License-Identifier: Apache-2.0
// What a render-farm operator sees: the serving farm's figures in the Prometheus text exposition
// format (version 0.0.4, https://prometheus.io/docs/instrumenting/exposition_formats/), written
// atomically into node_exporter's textfile collector folder (Debian's prometheus-node-exporter
// reads /var/lib/prometheus/node-exporter/*.prom), so no HTTP server of our own is needed.
//
// Metrics (all prefixed mogao_farm_; counters end in _total; seconds and rays are SI counts):
//   up (1 while serving, 0 once stopped)                 frames_total, frame_seconds (last frame)
//   frame_seconds_mean over the last kWindow frames      render_phase_seconds (last frame)
//   balance_efficiency (last frame, mean/max rank time)  rays_per_second (last frame)
//   rank_render_seconds{rank="N"} (last frame, MPI rank) render_ranks
//   sessions_active, sessions_opened_total, sessions_refused_total, sessions_revoked_total
//   connections_open, connections_unauthenticated, connections_accepted_total,
//   connections_refused_total{cap="max_connections|max_unauthenticated|max_unauthenticated_per_address"},
//   connections_aged_out_total (renderfarm/link/connection_guard.h)
//   requests_received_total, requests_invalid_total, requests_dropped_total,
//   requests_superseded_total, requests_degraded_total (request_policy.h), render_failures_total
//   frames_sent_total, jpeg_bytes_sent_total, last_frame_timestamp_seconds (Unix time)
//   certificate_not_after_seconds{role="ca|farm",name="<subject CN>"} (Unix time, each certificate
//   the farm serves with: LinkServerStats::certificates, renderfarm/link/cert_expiry.h)
//   crl_next_update_seconds (Unix time; only with a revocation list that has a nextUpdate)
// Errors: FarmMetrics::write throws std::runtime_error naming the file (common/file_io.h); the
// serve loop logs it and keeps serving.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <string>

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
    static constexpr std::size_t kWindow = 64;

    // One rendered frame (LiveFrame::stats) and when it was finished (Unix seconds).
    void observe_frame(const FrameStats& stats, double frame_seconds, double unix_seconds);

    // The exposition text for the frames seen so far and `counters`.
    [[nodiscard]] std::string text(const FarmCounters& counters) const;

    // text() written atomically to `file` (a reader never sees half a file).
    void write(const std::filesystem::path& file, const FarmCounters& counters) const;

private:
    std::uint64_t frames_ = 0;
    FrameStats last_;
    double last_seconds_ = 0.0;
    double last_unix_ = 0.0;
    std::deque<double> window_;
};

}  // namespace mogao
