// SPDX-License-Identifier: Apache-2.0
#include "kiosk/stats/kiosk_metrics.h"

#include <algorithm>

namespace mogao {
namespace {

using prometheus::TextWriter;

double count(std::uint64_t n) { return static_cast<double>(n); }

// A StateSet (OpenMetrics): one series per state, 1 for the current one, so that an alert or a
// panel matches the state by label and a state change is no new series.
void state_set(TextWriter& w, std::string_view name, std::string_view help, const std::vector<const char*>& states,
               std::string_view current) {
    w.family(name, "gauge", help);
    for (const char* s : states) w.sample(name, {{"state", s}}, current == s ? 1.0 : 0.0);
}

void link_families(TextWriter& w, const KioskStatus& s, const LinkClientStats& l) {
    state_set(w, "state", "the kiosk's state: connecting (no farm frame yet), showing, disconnected (last frame kept)",
              {"connecting", "showing", "disconnected", "stopped"}, s.state);
    w.gauge("link_connected", "1 while a session with the farm is open", s.connected ? 1.0 : 0.0);
    w.counter("link_sessions_opened_total", "sessions opened with the farm (reconnects = this - 1)",
              count(l.sessions_opened));
    w.counter("link_connect_failures_total", "connects refused or broken before a session", count(l.attempts_failed));
    w.counter("link_frames_received_total", "farm frames received", count(l.frames_received));
    w.counter("link_jpeg_bytes_received_total", "JPEG bytes received from the farm", count(l.bytes_received));
    w.gauge("farm_silent_seconds", "since the last farm frame (0 before the first)", s.farm_silent_s);
}

void calibration_families(TextWriter& w, const KioskStatus& s, const KioskCounters& c) {
    w.gauge("calibration_loaded_timestamp_seconds", "Unix time the calibration on the wall was loaded",
            double(s.calibration.loaded_ns) * 1e-9);
    const std::uint64_t selfcal = std::min(c.selfcal_swaps, s.calibration.swaps);
    w.family("calibration_swaps_total", "counter", "calibrations swapped in while running, by where they came from");
    w.sample("calibration_swaps_total", {{"source", "file"}}, count(s.calibration.swaps - selfcal));
    w.sample("calibration_swaps_total", {{"source", "selfcal"}}, count(selfcal));
    w.counter("calibration_refused_total", "calibration updates refused (the last good one kept)",
              count(s.calibration.refused));
    if (!s.selfcal) return;
    state_set(w, "selfcal_state", "self-recalibration's state",
              {"calibrated", "drift_detected", "correcting", "cannot_correct"}, selfcal::to_key(s.selfcal->state));
    w.counter("selfcal_corrections_total", "corrections self-recalibration began", count(c.selfcal_corrections));
    w.family("selfcal_drift_pixels", "gauge", "each projector's filtered drift on the screen, its own pixels");
    for (const selfcal::ProjectorStatus& p : s.selfcal->projectors)
        w.sample("selfcal_drift_pixels", {{"projector", p.id}}, p.drift_px);
}

}  // namespace

const std::vector<double>& motion_to_photon_buckets() {
    static const std::vector<double> buckets{0.02, 0.035, 0.05, 0.075, 0.1, 0.15, 0.2, 0.3, 0.5, 1, 2};
    return buckets;
}

std::string kiosk_metrics_text(const KioskStatus& s, const KioskCounters& c) {
    TextWriter w("mogao_kiosk_");
    w.gauge("up", "1 while the kiosk runs, 0 after its clean stop (stale when last_update_timestamp_seconds is old)",
            s.state == "stopped" ? 0.0 : 1.0);
    const double written_s = double(s.written_ns) * 1e-9;
    w.gauge("last_update_timestamp_seconds", "Unix time this file was written", written_s);
    w.gauge("start_time_seconds", "Unix time the kiosk's loop started", written_s - s.uptime_s);
    w.family("build_info", "gauge", "the kiosk's version, as a label; always 1");
    w.sample("build_info", {{"version", c.version}}, 1);
    link_families(w, s, c.link);
    w.counter("frames_shown_total", "farm frames on screen on every output", count(s.frames_shown));
    w.counter("frames_dropped_total", "farm frames that failed to decode (the last good one kept)",
              count(c.frames_dropped));
    if (c.motion_to_photon != nullptr)
        w.histogram("motion_to_photon_seconds", "view request stamped (pose sampled) to every output presenting it",
                    *c.motion_to_photon);
    calibration_families(w, s, c);
    if (!s.certificates.empty()) {
        w.family("certificate_not_after_seconds", "gauge",
                 "notAfter of each certificate the link holds (the farm CA, this appliance's own), Unix time");
        for (const CertificateExpiry& e : s.certificates)
            w.sample("certificate_not_after_seconds", {{"role", e.role}, {"name", e.name}}, double(e.not_after_s));
    }
    return w.text();
}

void write_kiosk_metrics(const std::filesystem::path& file, const KioskStatus& status, const KioskCounters& counters) {
    prometheus::write_textfile(file, kiosk_metrics_text(status, counters));
}

}  // namespace mogao
