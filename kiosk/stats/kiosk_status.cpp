// SPDX-License-Identifier: Apache-2.0
#include "kiosk/stats/kiosk_status.h"

#include <cmath>
#include <ctime>
#include <span>

#include <fmt/format.h>

#include "common/file_io.h"

namespace mogao {

std::string utc_text(std::int64_t realtime_ns) {
    const std::time_t seconds = static_cast<std::time_t>(realtime_ns / 1'000'000'000);
    std::tm utc{};
    if (::gmtime_r(&seconds, &utc) == nullptr) return "";
    return fmt::format("{:04}-{:02}-{:02}T{:02}:{:02}:{:02}Z", utc.tm_year + 1900, utc.tm_mon + 1, utc.tm_mday,
                       utc.tm_hour, utc.tm_min, utc.tm_sec);
}

namespace {

nlohmann::json selfcal_json(const std::optional<selfcal::SelfcalStatus>& s) {
    if (!s) return {{"enabled", false}};
    nlohmann::json projectors = nlohmann::json::array();
    for (const auto& p : s->projectors) {
        projectors.push_back({{"id", p.id},
                              {"matches", p.matches},
                              {"measured", p.measured},
                              {"drift_px", p.drift_px},
                              {"rotation_deg", p.rotation_deg},
                              {"shift_mm", p.shift_mm}});
    }
    return {{"enabled", true},
            {"state", selfcal::to_key(s->state)},
            {"t_s", s->t_s},
            {"waiting", s->waiting},
            {"reason", s->reason},
            {"camera_rotation_deg", s->camera_rotation_deg},
            {"projectors", projectors},
            {"line", s->text()}};
}

nlohmann::json certificates_json(const KioskStatus& s) {
    const std::int64_t now_s = s.written_ns / 1'000'000'000;
    nlohmann::json out = nlohmann::json::array();
    for (const CertificateExpiry& c : s.certificates) {
        out.push_back(
            {{"role", c.role},
             {"name", c.name},
             {"not_after_s", c.not_after_s},
             {"not_after_utc", utc_seconds_text(c.not_after_s)},
             {"days_left", days_left(c.not_after_s, now_s)},
             {"expires_soon", expires_soon(c, now_s, certificate_warning_seconds(s)) || c.not_after_s <= now_s}});
    }
    return out;
}

}  // namespace

std::int64_t certificate_warning_seconds(const KioskStatus& status) {
    return status.certificate_warning_days > 0 ? std::llround(status.certificate_warning_days * 86'400.0) : 0;
}

nlohmann::json kiosk_status_json(const KioskStatus& s) {
    nlohmann::json calibration = {{"source", s.calibration.source},
                                  {"loaded_ns", s.calibration.loaded_ns},
                                  {"loaded_utc", utc_text(s.calibration.loaded_ns)},
                                  {"swaps", s.calibration.swaps},
                                  {"refused", s.calibration.refused},
                                  {"last_error", s.calibration.last_error}};
    if (!s.calibration.last_error.empty()) {
        calibration["last_error_ns"] = s.calibration.last_error_ns;
        calibration["last_error_utc"] = utc_text(s.calibration.last_error_ns);
    }
    nlohmann::json last_error = nullptr;
    if (!s.last_error.empty()) {
        last_error = {{"what", s.last_error}, {"ns", s.last_error_ns}, {"utc", utc_text(s.last_error_ns)}};
    }
    return {{"written_ns", s.written_ns},
            {"written_utc", utc_text(s.written_ns)},
            {"uptime_s", s.uptime_s},
            {"state", s.state},
            {"farm", {{"endpoint", s.endpoint}, {"connected", s.connected}, {"silent_s", s.farm_silent_s}}},
            {"on_wall", s.on_wall},
            {"fallbacks", s.fallbacks},
            {"frames_shown", s.frames_shown},
            {"showing_request", s.showing_request},
            {"fps", s.fps},
            {"latency_mean_ms", s.latency_mean_ms},
            {"latency_p95_ms", s.latency_p95_ms},
            {"last_error", last_error},
            {"calibration", calibration},
            {"selfcal", selfcal_json(s.selfcal)},
            {"certificates", certificates_json(s)}};
}

void write_kiosk_status(const std::filesystem::path& file, const KioskStatus& status) {
    const std::string text = kiosk_status_json(status).dump(2) + "\n";
    write_file_atomically(file, std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

}  // namespace mogao
