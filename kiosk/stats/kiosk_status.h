// SPDX-License-Identifier: Apache-2.0
// The kiosk's status file (docs/kiosk.md, "Status file"): what a technician (or a monitoring
// agent) reads to see the appliance's state without the journal -- the farm connection, the frames
// on screen, the calibration on the wall (file, when it was loaded, the last refused update) and
// the self-recalibration state (appliance/selfcal/selfcal_status.h). One JSON object, rewritten
// atomically (common/file_io.h: temporary + fsync + rename) every [stats].status_period_s by the
// display loop and once at the clean stop, so a reader never sees half a file.
//
// Times: "*_ns" are CLOCK_REALTIME nanoseconds since the epoch, "*_utc" the same as ISO 8601 UTC
// ("2026-11-22T12:30:05Z"); "uptime_s" is seconds since the kiosk's loop started; a certificate's
// "not_after_s" is seconds since the epoch (X.509's resolution), "days_left" counted from
// written_ns.
// Errors: write_kiosk_status throws std::system_error naming the file (the kiosk logs it as a
// warning, once per kind of failure, and goes on showing).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "appliance/selfcal/selfcal_status.h"
#include "renderfarm/link/cert_expiry.h"

namespace mogao {

// The calibration on the wall (the kiosk keeps it; the status file and the journal show it).
struct CalibrationInUse {
    std::string source;              // the MPCDI path, "ideal", "selfcal"
    std::int64_t loaded_ns = 0;      // CLOCK_REALTIME, when it was loaded
    std::string last_error;          // the latest refused update since it was loaded; empty: none
    std::int64_t last_error_ns = 0;  // when that was
    std::uint64_t swaps = 0;         // calibrations swapped in since start
    std::uint64_t refused = 0;       // updates refused since start
};

// Everything the status file shows, gathered by the loop.
struct KioskStatus {
    std::int64_t written_ns = 0;
    double uptime_s = 0.0;
    std::string
        state;  // "connecting" (no farm frame yet), "showing", "disconnected" (showing the last frame), "stopped"
    std::string endpoint;
    bool connected = false;
    std::uint64_t frames_shown = 0;     // farm frames on screen on every output since start
    std::uint64_t showing_request = 0;  // the request id on screen (0: the connecting screen)
    CalibrationInUse calibration;
    std::optional<selfcal::SelfcalStatus> selfcal;  // nullopt: self-recalibration off
    std::vector<std::string> on_wall;               // the lines drawn on the wall now (kiosk/display/on_wall_status.h)
    double farm_silent_s = 0.0;                     // since the last farm frame (0 before the first)
    std::vector<std::string> fallbacks;             // bad start-up files replaced by last good copies
    // Over the display statistics' sliding window (kiosk_stats.h; 0 before two frames):
    double fps = 0.0;              // farm frames presented per second
    double latency_mean_ms = 0.0;  // motion-to-photon, request to presented: mean
    double latency_p95_ms = 0.0;   // and 95th percentile
    // The latest error outside the calibration's (a dropped frame, a refused view request, a file
    // the kiosk could not write): what the journal said, and when. Empty: none since start.
    std::string last_error;
    std::int64_t last_error_ns = 0;
    // The certificates the link holds (the farm CA, this appliance's own; LinkClientStats), and how
    // long before its notAfter one is flagged (status file "expires_soon", on-wall warning line;
    // [status].certificate_warning_days; 0: never).
    std::vector<CertificateExpiry> certificates;
    double certificate_warning_days = 30.0;
};

// certificate_warning_days in whole seconds (0 for none or negative).
[[nodiscard]] std::int64_t certificate_warning_seconds(const KioskStatus& status);

// "2026-11-22T12:30:05Z" (seconds, UTC) for CLOCK_REALTIME nanoseconds.
[[nodiscard]] std::string utc_text(std::int64_t realtime_ns);

// The file's JSON (schema in docs/kiosk.md). Pure.
[[nodiscard]] nlohmann::json kiosk_status_json(const KioskStatus& status);

// Writes kiosk_status_json(status) to `file` atomically (the folder must exist).
void write_kiosk_status(const std::filesystem::path& file, const KioskStatus& status);

}  // namespace mogao
