// SPDX-License-Identifier: Apache-2.0
// The kiosk's metrics for node_exporter's textfile collector ([stats].metrics_file, e.g.
// /run/mogao/kiosk.prom in the unit's RuntimeDirectory): the Prometheus text format
// (common/prometheus_text.h), rewritten atomically (mode 0644) with the status file every
// [stats].status_period_s and once at the clean stop (up 0). docs/monitoring.md lists every
// series, its type, labels and unit, and the alert rules that read them.
//
// Metrics (all prefixed mogao_kiosk_):
//   up (1 while running, 0 after the clean stop), last_update_timestamp_seconds (Unix time of the
//   file: a kiosk that died without a clean stop leaves it to age), start_time_seconds,
//   build_info{version} 1
//   state{state="connecting|showing|disconnected|stopped"} (1 for the current one, 0 for the others)
//   link_connected, link_sessions_opened_total, link_connect_failures_total, link_frames_received_total,
//   link_jpeg_bytes_received_total, farm_silent_seconds (since the last farm frame; 0 before the first)
//   frames_shown_total (on every output), frames_dropped_total (failed to decode; the last good kept)
//   motion_to_photon_seconds (histogram: view request stamped -> every output presented the frame,
//     kiosk_stats.h)
//   calibration_loaded_timestamp_seconds, calibration_swaps_total{source="file|selfcal"},
//   calibration_refused_total
//   selfcal_state{state="calibrated|drift_detected|correcting|cannot_correct"},
//   selfcal_corrections_total (times self-recalibration began a correction),
//   selfcal_drift_pixels{projector} (filtered drift, the projector's own pixels) -- only with [selfcal]
//   certificate_not_after_seconds{role="ca|appliance",name="<subject CN>"} (Unix time)
// Temperatures are node_exporter's own (hwmon, thermal_zone collectors), where the hardware has them.
// Errors: write_kiosk_metrics throws std::system_error naming the file (the kiosk logs it once per
// kind of failure and goes on showing).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "common/prometheus_text.h"
#include "kiosk/stats/kiosk_status.h"
#include "renderfarm/link/link_client.h"

namespace mogao {

// Upper bounds of the motion-to-photon histogram, seconds: 20 ms (a fast LAN farm on KMS) to 2 s
// (a software rasteriser over a slow link).
[[nodiscard]] const std::vector<double>& motion_to_photon_buckets();

// What the metrics add to the status file's figures (KioskStatus).
struct KioskCounters {
    const prometheus::Histogram* motion_to_photon = nullptr;  // KioskStats::motion_to_photon(); null: none
    LinkClientStats link;
    std::uint64_t frames_dropped = 0;       // frames that failed to decode
    std::uint64_t selfcal_corrections = 0;  // SelfcalWorker::corrections()
    std::uint64_t selfcal_swaps = 0;        // of status.calibration.swaps, those from self-recalibration
    std::string version;                    // build_info's label
};

// The exposition text. Pure. up is status.state != "stopped".
[[nodiscard]] std::string kiosk_metrics_text(const KioskStatus& status, const KioskCounters& counters);

// kiosk_metrics_text written atomically to `file` (the folder must exist).
void write_kiosk_metrics(const std::filesystem::path& file, const KioskStatus& status, const KioskCounters& counters);

}  // namespace mogao
