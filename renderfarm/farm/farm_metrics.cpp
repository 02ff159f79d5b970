// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/farm_metrics.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

namespace mogao {
namespace {

using prometheus::Labels;
using prometheus::TextWriter;

// Frame times from a fast preview (10 ms) to a progressive still far past the default 1 s budget.
const std::vector<double> kFrameSecondsBuckets{0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1, 2.5, 5, 10, 30};
// mean / max rank time: 1 is perfect balance; PBT keeps it near 0.9 on a warm cost map.
const std::vector<double> kEfficiencyBuckets{0.5, 0.6, 0.7, 0.8, 0.85, 0.9, 0.95, 0.99, 1};

double count(std::uint64_t n) { return static_cast<double>(n); }

// notAfter of each certificate the farm serves with, Unix seconds: an alert can fire weeks ahead.
void certificates(TextWriter& w, const std::vector<CertificateExpiry>& certs) {
    if (certs.empty()) return;
    w.family("certificate_not_after_seconds", "gauge",
             "notAfter of each certificate the farm holds (the CA bundle, its serving certificate), Unix time");
    for (const auto& c : certs)
        w.sample("certificate_not_after_seconds", {{"role", c.role}, {"name", c.name}}, double(c.not_after_s));
}

void session_families(TextWriter& w, const LinkServerStats& l) {
    w.gauge("sessions_active", "appliance sessions open now", count(l.sessions_active));
    w.counter("sessions_opened_total", "sessions that passed TLS and the farm's checks", count(l.sessions_opened));
    w.counter("sessions_refused_total", "sessions refused: IPv4, not allowed, revoked, over a cap",
              count(l.sessions_refused));
    w.counter("sessions_revoked_total", "open sessions ended by a revocation", count(l.sessions_revoked));
    const ConnectionGuardStats& k = l.connections;
    w.gauge("connections_open", "TCP connections open now (connection_guard.h)", count(k.open));
    w.gauge("connections_unauthenticated", "open connections without an admitted session (TLS handshakes included)",
            count(k.unauthenticated));
    w.counter("connections_accepted_total", "TCP connections handed to gRPC", count(k.accepted));
    w.family("connections_refused_total", "counter",
             "TCP connections closed before any TLS, by the cap they were over");
    w.sample("connections_refused_total", {{"cap", "max_connections"}}, count(k.refused_open));
    w.sample("connections_refused_total", {{"cap", "max_unauthenticated"}}, count(k.refused_unauthenticated));
    w.sample("connections_refused_total", {{"cap", "max_unauthenticated_per_address"}}, count(k.refused_per_address));
    w.counter("connections_aged_out_total", "connections shut down for opening no session in time", count(k.aged_out));
}

void request_families(TextWriter& w, const FarmCounters& c) {
    const LinkServerStats& l = c.link;
    w.counter("requests_received_total", "valid view requests read", count(l.requests_received));
    w.counter("requests_invalid_total", "view requests refused by validation", count(l.requests_invalid));
    w.counter("requests_dropped_total", "stale view requests dropped by the link", count(l.requests_dropped));
    w.counter("requests_superseded_total", "requests replaced by a newer one in the farm's queue", count(c.superseded));
    w.counter("requests_degraded_total", "requests over the farm's bounds, rendered degraded", count(c.degraded));
    w.counter("render_failures_total", "requests whose render failed", count(l.render_failures));
    w.counter("frames_sent_total", "JPEG frames sent to appliances", count(l.frames_sent));
    w.counter("jpeg_bytes_sent_total", "JPEG bytes sent to appliances", count(l.jpeg_bytes_sent));
}

}  // namespace

FarmMetrics::FarmMetrics(std::string version)
    : version_(std::move(version)),
      frame_seconds_(kFrameSecondsBuckets),
      render_phase_seconds_(kFrameSecondsBuckets),
      balance_efficiency_(kEfficiencyBuckets) {}

const std::string& FarmMetrics::appliance_label(const std::string& appliance) {
    static const std::string unknown = "unknown", other = "other";
    if (appliance.empty()) return unknown;
    if (appliances_.contains(appliance) || appliances_.size() < kMaxApplianceLabels) return appliance;
    return other;
}

void FarmMetrics::observe_frame(const FrameStats& stats, double frame_seconds, double unix_seconds,
                                const std::string& appliance) {
    ++frames_;
    if (stats.tiles_cut > 0) ++frames_cut_;
    rays_ += stats.rays;
    frame_seconds_.observe(frame_seconds);
    render_phase_seconds_.observe(stats.render_phase_seconds);
    balance_efficiency_.observe(stats.balance_efficiency);
    if (rank_render_seconds_.size() < stats.rank_render_seconds.size())
        rank_render_seconds_.resize(stats.rank_render_seconds.size(), 0.0);
    for (std::size_t r = 0; r < stats.rank_render_seconds.size(); ++r) {
        // A counter never goes down: a rank's unmeasured (NaN) or nonsense time adds nothing.
        if (std::isfinite(stats.rank_render_seconds[r]) && stats.rank_render_seconds[r] > 0)
            rank_render_seconds_[r] += stats.rank_render_seconds[r];
    }
    PerAppliance& a = appliances_[appliance_label(appliance)];
    ++a.frames;
    if (std::isfinite(frame_seconds) && frame_seconds > 0) a.seconds += frame_seconds;
    last_unix_ = unix_seconds;
}

void FarmMetrics::frame_families(TextWriter& w) const {
    w.counter("frames_total", "frames rendered (or sent from a converged accumulation)", count(frames_));
    w.histogram("frame_seconds", "each frame's time on the admin: render, composite, accumulate", frame_seconds_);
    w.histogram("render_phase_seconds", "each frame: rects sent to the last rank's pixels in", render_phase_seconds_);
    w.histogram("balance_efficiency", "each frame: mean / max render-rank time (1 = perfectly balanced)",
                balance_efficiency_);
    w.counter("rays_total", "rays traced: camera, shadow, ambient occlusion, bounce", count(rays_));
    w.counter("frames_cut_total", "frames cut at the frame budget (some tiles rendered coarse)", count(frames_cut_));
    w.family("rank_render_seconds_total", "counter", "render time of each render rank (MPI rank), summed over frames");
    for (std::size_t r = 0; r < rank_render_seconds_.size(); ++r)
        w.sample("rank_render_seconds_total", {{"rank", std::to_string(r + 1)}}, rank_render_seconds_[r]);
    w.family("appliance_frames_total", "counter",
             "frames rendered for each appliance (certificate CN; at most 32 names, the rest \"other\")");
    for (const auto& [name, a] : appliances_)
        w.sample("appliance_frames_total", {{"appliance", name}}, count(a.frames));
    w.family("appliance_frame_seconds_total", "counter", "admin time of the frames rendered for each appliance");
    for (const auto& [name, a] : appliances_)
        w.sample("appliance_frame_seconds_total", {{"appliance", name}}, a.seconds);
    w.gauge("last_frame_timestamp_seconds", "Unix time the last frame was finished", last_unix_);
}

std::string FarmMetrics::text(const FarmCounters& c, double now_unix_seconds) const {
    TextWriter w("mogao_farm_");
    w.gauge("up", "1 while the farm serves, 0 once it stopped (stale when last_update_timestamp_seconds is old)",
            c.up ? 1.0 : 0.0);
    w.gauge("last_update_timestamp_seconds", "Unix time this file was written (about every second while serving)",
            now_unix_seconds);
    w.family("build_info", "gauge", "the farm's version, as a label; always 1");
    w.sample("build_info", {{"version", version_}}, 1);
    w.gauge("render_ranks", "MPI ranks that trace", c.render_ranks);
    frame_families(w);
    session_families(w, c.link);
    request_families(w, c);
    certificates(w, c.link.certificates);
    if (c.link.crl_next_update_s != 0)
        w.gauge("crl_next_update_seconds", "nextUpdate of the revocation list in force, Unix time (re-issue it before)",
                double(c.link.crl_next_update_s));
    return w.text();
}

void FarmMetrics::write(const std::filesystem::path& file, const FarmCounters& counters,
                        double now_unix_seconds) const {
    prometheus::write_textfile(file, text(counters, now_unix_seconds));
}

namespace {
std::atomic<FarmMetricsFile*> g_current_file{nullptr};  // lock-free: read from signal handlers

double unix_now() { return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count(); }

// Temporary, fchmod, write, rename: each async-signal-safe (signal-safety(7)), so that a signal
// handler may call it; no allocation, no lock, errno left as found (0 on success, else the failing
// call's, in `*error`). No fsync: a gauge file keeps nothing worth a power cut (the farm rewrites it
// at its next start, and its timestamp tells staleness), while an fsync on a busy disk can take
// seconds, and mpirun SIGKILLs the admin one second after a stop: the rename must land before that.
bool replace_file(const char* tmp, const char* file, const std::string& text, int* error = nullptr) noexcept {
    const int saved_errno = errno;
    const int fd = ::open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    bool ok = fd >= 0 && ::fchmod(fd, 0644) == 0;
    for (std::size_t done = 0; ok && done < text.size();) {
        const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
        if (n < 0 && errno == EINTR) continue;
        ok = n > 0;
        if (ok) done += static_cast<std::size_t>(n);
    }
    if (fd >= 0) ok = ::close(fd) == 0 && ok;
    ok = ok && ::rename(tmp, file) == 0;
    if (error != nullptr) *error = ok ? 0 : errno;
    if (!ok) ::unlink(tmp);
    errno = saved_errno;
    return ok;
}
}  // namespace

FarmMetricsFile::FarmMetricsFile(std::filesystem::path file) : file_(std::move(file)) {
    if (file_.empty()) return;
    const std::string stem = (file_.parent_path() / ("." + file_.filename().string())).string();
    down_tmp_ = stem + ".down." + std::to_string(::getpid());
    up_tmp_ = stem + ".up." + std::to_string(::getpid());
    g_current_file = this;
    previous_ = std::set_terminate(&FarmMetricsFile::on_terminate);
}

FarmMetricsFile::~FarmMetricsFile() {
    if (file_.empty()) return;
    FarmMetricsFile* self = this;
    if (g_current_file.compare_exchange_strong(self, nullptr)) std::set_terminate(previous_);
    if (!write_down()) spdlog::warn("metrics: cannot write {} with up 0", file_.string());
}

void FarmMetricsFile::on_terminate() {
    if (FarmMetricsFile* file = g_current_file.exchange(nullptr)) {
        (void)file->write_down();
        if (file->previous_ != nullptr) file->previous_();
    }
    std::abort();
}

void FarmMetricsFile::on_stop_signal() noexcept {
    if (FarmMetricsFile* file = g_current_file.load()) {
        file->stopping_ = true;
        (void)file->write_down();
    }
}

bool FarmMetricsFile::write_down(bool again, int* error) noexcept {
    // Skipped while update() is changing the text (a signal or terminate from inside it): the loop's
    // own last update, or staleness, tells then.
    if (busy_.test_and_set()) return false;
    bool ok = true;
    if (!down_text_.empty() && (again || !wrote_down_))
        ok = wrote_down_ = replace_file(down_tmp_.c_str(), file_.c_str(), down_text_, error);
    busy_.clear();
    return ok;
}

void FarmMetricsFile::update(const FarmMetrics& metrics, const FarmCounters& counters) {
    if (file_.empty()) return;
    const double now = unix_now();
    FarmCounters written = counters;
    written.up = counters.up && !stopping_;  // never 1 again once a stop signal came
    const bool writes_up = written.up;
    const std::string text = metrics.text(written, now);
    written.up = false;
    std::string down = metrics.text(written, now);
    if (busy_.test_and_set()) return;  // only from inside a handler's write: the handler tells
    down_text_ = std::move(down);      // the handlers' text from now on: these counts with up 0
    wrote_down_ = false;
    busy_.clear();
    int error = 0;
    if (writes_up && !stopping_) (void)replace_file(up_tmp_.c_str(), file_.c_str(), text, &error);
    // A stop signal during that write found the file saying up 0 and wrote its down text, which the
    // rename then replaced with up 1: say down again, microseconds later (no fsync on either path).
    if (!writes_up || stopping_) (void)write_down(/*again=*/true, &error);
    const std::string message = error == 0 ? "" : "cannot write " + file_.string() + ": " + std::strerror(error);
    if (!message.empty() && message != last_error_) spdlog::warn("metrics: {}", message);
    last_error_ = message;
}

}  // namespace mogao
