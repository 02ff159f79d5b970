// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/farm_metrics.h"

#include <cmath>
#include <numeric>
#include <span>

#include <fmt/format.h>

#include "common/file_io.h"

namespace mogao {
namespace {

// A sample value as the exposition format spells it (Go's ParseFloat: NaN, +Inf, -Inf).
std::string number(double v) {
    if (std::isnan(v)) return "NaN";
    if (std::isinf(v)) return v > 0 ? "+Inf" : "-Inf";
    return fmt::format("{}", v);
}

// One metric family: HELP, TYPE and one sample without labels.
void family(std::string& out, const char* name, const char* type, const char* help, double value) {
    fmt::format_to(std::back_inserter(out), "# HELP mogao_farm_{} {}\n# TYPE mogao_farm_{} {}\nmogao_farm_{} {}\n",
                   name, help, name, type, name, number(value));
}

void counter(std::string& out, const char* name, const char* help, std::uint64_t value) {
    family(out, name, "counter", help, static_cast<double>(value));
}

void gauge(std::string& out, const char* name, const char* help, double value) {
    family(out, name, "gauge", help, value);
}

// A label value as the exposition format escapes it: backslash, double quote, line feed.
std::string label_value(const std::string& text) {
    std::string out;
    for (const char c : text) {
        if (c == '\\' || c == '"') out += '\\';
        out += c == '\n' ? std::string("\\n") : std::string(1, c);
    }
    return out;
}

// notAfter of each certificate the farm serves with, Unix seconds: an alert can fire weeks ahead.
void certificates(std::string& out, const std::vector<CertificateExpiry>& certs) {
    if (certs.empty()) return;
    out +=
        "# HELP mogao_farm_certificate_not_after_seconds notAfter of each certificate the farm holds (the CA "
        "bundle, its serving certificate), Unix time\n"
        "# TYPE mogao_farm_certificate_not_after_seconds gauge\n";
    for (const auto& c : certs)
        fmt::format_to(std::back_inserter(out),
                       "mogao_farm_certificate_not_after_seconds{{role=\"{}\",name=\"{}\"}} {}\n", label_value(c.role),
                       label_value(c.name), c.not_after_s);
}

}  // namespace

void FarmMetrics::observe_frame(const FrameStats& stats, double frame_seconds, double unix_seconds) {
    ++frames_;
    last_ = stats;
    last_seconds_ = frame_seconds;
    last_unix_ = unix_seconds;
    window_.push_back(frame_seconds);
    if (window_.size() > kWindow) window_.pop_front();
}

std::string FarmMetrics::text(const FarmCounters& c) const {
    std::string out;
    const LinkServerStats& l = c.link;
    gauge(out, "up", "1 while the farm serves, 0 once it stopped", c.up ? 1.0 : 0.0);
    gauge(out, "render_ranks", "MPI ranks that trace", c.render_ranks);
    counter(out, "frames_total", "frames rendered (or sent from a converged accumulation)", frames_);
    gauge(out, "frame_seconds", "the last frame's time on the admin: render, composite, accumulate", last_seconds_);
    const double mean =
        window_.empty() ? 0.0 : std::accumulate(window_.begin(), window_.end(), 0.0) / double(window_.size());
    gauge(out, "frame_seconds_mean", "mean frame time over the last 64 frames", mean);
    gauge(out, "render_phase_seconds", "the last frame: rects sent to last rank's pixels in",
          last_.render_phase_seconds);
    gauge(out, "balance_efficiency", "the last frame: mean / max render-rank time (1 = perfectly balanced)",
          last_.balance_efficiency);
    gauge(out, "rays_per_second", "the last frame: rays traced / render phase", last_.rays_per_second);
    out +=
        "# HELP mogao_farm_rank_render_seconds the last frame's render time of each render rank\n"
        "# TYPE mogao_farm_rank_render_seconds gauge\n";
    for (std::size_t r = 0; r < last_.rank_render_seconds.size(); ++r)
        fmt::format_to(std::back_inserter(out), "mogao_farm_rank_render_seconds{{rank=\"{}\"}} {}\n", r + 1,
                       number(last_.rank_render_seconds[r]));
    gauge(out, "last_frame_timestamp_seconds", "Unix time the last frame was finished", last_unix_);
    gauge(out, "sessions_active", "appliance sessions open now", static_cast<double>(l.sessions_active));
    counter(out, "sessions_opened_total", "sessions that passed TLS and the farm's checks", l.sessions_opened);
    counter(out, "sessions_refused_total", "sessions refused: IPv4, not allowed, revoked, over a cap",
            l.sessions_refused);
    counter(out, "sessions_revoked_total", "open sessions ended by a revocation", l.sessions_revoked);
    const ConnectionGuardStats& k = l.connections;
    gauge(out, "connections_open", "TCP connections open now (connection_guard.h)", static_cast<double>(k.open));
    gauge(out, "connections_unauthenticated", "open connections without an admitted session (TLS handshakes included)",
          static_cast<double>(k.unauthenticated));
    counter(out, "connections_accepted_total", "TCP connections handed to gRPC", k.accepted);
    out +=
        "# HELP mogao_farm_connections_refused_total TCP connections closed before any TLS, by the cap they were over\n"
        "# TYPE mogao_farm_connections_refused_total counter\n";
    for (const auto& [cap, n] :
         {std::pair{"max_connections", k.refused_open}, std::pair{"max_unauthenticated", k.refused_unauthenticated},
          std::pair{"max_unauthenticated_per_address", k.refused_per_address}})
        fmt::format_to(std::back_inserter(out), "mogao_farm_connections_refused_total{{cap=\"{}\"}} {}\n", cap, n);
    counter(out, "connections_aged_out_total", "connections shut down for opening no session in time", k.aged_out);
    counter(out, "requests_received_total", "valid view requests read", l.requests_received);
    counter(out, "requests_invalid_total", "view requests refused by validation", l.requests_invalid);
    counter(out, "requests_dropped_total", "stale view requests dropped by the link", l.requests_dropped);
    counter(out, "requests_superseded_total", "requests replaced by a newer one in the farm's queue", c.superseded);
    counter(out, "requests_degraded_total", "requests over the farm's bounds, rendered degraded", c.degraded);
    counter(out, "render_failures_total", "requests whose render failed", l.render_failures);
    counter(out, "frames_sent_total", "JPEG frames sent to appliances", l.frames_sent);
    counter(out, "jpeg_bytes_sent_total", "JPEG bytes sent to appliances", l.jpeg_bytes_sent);
    certificates(out, l.certificates);
    if (l.crl_next_update_s != 0)
        gauge(out, "crl_next_update_seconds",
              "nextUpdate of the revocation list in force, Unix time (re-issue it before)",
              static_cast<double>(l.crl_next_update_s));
    return out;
}

void FarmMetrics::write(const std::filesystem::path& file, const FarmCounters& counters) const {
    const std::string body = text(counters);
    write_file_atomically(file, std::span(reinterpret_cast<const std::uint8_t*>(body.data()), body.size()));
}

}  // namespace mogao
