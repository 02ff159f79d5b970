// SPDX-License-Identifier: Apache-2.0
#include "kiosk/display/on_wall_status.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include <fmt/format.h>

#include "appliance/warp/warp_sampling.h"
#include "kiosk/display/bitmap_font.h"

namespace mogao {
namespace {

constexpr std::size_t kMaxLine = 36;

// Upper case, only what the font draws (others become spaces: '?' would look like an error), cut.
std::string wall_text(const std::string& text) {
    std::string out;
    for (const char c : text) {
        const char u = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
        const bool known = (u >= 'A' && u <= 'Z') || (u >= '0' && u <= '9') ||
                           std::string_view(" .:-/[]_=").find(u) != std::string_view::npos;
        out += known ? u : ' ';
    }
    if (out.size() > kMaxLine) out = out.substr(0, kMaxLine - 3) + "...";
    return out;
}

std::string selfcal_line(const KioskStatus& s) {
    if (!s.selfcal) return "SELFCAL OFF";
    double worst = 0.0;
    for (const auto& p : s.selfcal->projectors) worst = std::max(worst, p.drift_px);
    if (s.selfcal->waiting) return wall_text(fmt::format("SELFCAL WAITING - {}", s.selfcal->reason));
    switch (s.selfcal->state) {
        case selfcal::SelfcalState::calibrated:
            return fmt::format("SELFCAL CALIBRATED - DRIFT {:.2f} PX", worst);
        case selfcal::SelfcalState::drift_detected:
            return fmt::format("SELFCAL DRIFT DETECTED - {:.2f} PX", worst);
        case selfcal::SelfcalState::correcting:
            return "SELFCAL CORRECTING";
        case selfcal::SelfcalState::cannot_correct:
            return "SELFCAL CANNOT CORRECT - RECALIBRATE";
    }
    return "SELFCAL ?";
}

std::string certificate_words(const std::string& role) {
    if (role == "ca") return "FARM CA CERT";
    if (role == "appliance") return "APPLIANCE CERT";
    return wall_text(role) + " CERT";
}

// One warning line per certificate within the warning period or expired; otherwise one line with the days
// left of the first to expire (nothing when the link reported none).
std::vector<std::string> certificate_lines(const KioskStatus& s) {
    std::vector<std::string> lines;
    if (s.certificates.empty()) return lines;
    const std::int64_t now_s = s.written_ns / 1'000'000'000;
    const std::int64_t within_s = certificate_warning_seconds(s);
    std::int64_t soonest = s.certificates.front().not_after_s;
    for (const CertificateExpiry& c : s.certificates) {
        soonest = std::min(soonest, c.not_after_s);
        if (!expires_soon(c, now_s, within_s) && c.not_after_s > now_s) continue;  // expired: always said
        const std::int64_t days = days_left(c.not_after_s, now_s);
        const std::string when = c.not_after_s <= now_s ? fmt::format("EXPIRED {} DAYS AGO", -days)
                                 : days == 0            ? std::string("EXPIRES TODAY")
                                                        : fmt::format("EXPIRES IN {} DAYS", days);
        lines.push_back(wall_text(certificate_words(c.role) + " " + when));
    }
    if (lines.empty()) lines.push_back(fmt::format("CERTIFICATES OK - {} DAYS LEFT", days_left(soonest, now_s)));
    return lines;
}

}  // namespace

std::vector<std::string> status_panel_lines(const KioskStatus& s) {
    std::vector<std::string> lines;
    lines.push_back(selfcal_line(s));
    lines.push_back(wall_text(fmt::format("FARM {} {}", s.connected ? "UP" : "DOWN", s.endpoint)));
    const std::string source = s.calibration.source.find('/') == std::string::npos
                                   ? s.calibration.source
                                   : s.calibration.source.substr(s.calibration.source.rfind('/') + 1);
    lines.push_back(wall_text(fmt::format("CALIBRATION {} - {} SWAPS", source, s.calibration.swaps)));
    lines.push_back(s.calibration.last_error.empty() ? std::string("LAST CALIBRATION ERROR: NONE")
                                                     : wall_text("LAST ERROR: " + s.calibration.last_error));
    for (std::string& line : certificate_lines(s)) lines.push_back(std::move(line));
    return lines;
}

std::string farm_lost_line(double lost_s) {
    return fmt::format("FARM LOST {} S - LAST FRAME", static_cast<long long>(std::floor(std::max(0.0, lost_s))));
}

void draw_on_wall(Rgb8Image& content, const ScreenCalibration& screen, const std::vector<std::string>& lines) {
    if (lines.empty() || content.size.width <= 0 || content.size.height <= 0) return;
    int widest = 0;  // at scale 1
    for (const auto& l : lines) widest = std::max(widest, text_width(l, 1));
    for (const ProjectorCalibration& p : screen.projectors) {
        const double row = 0.8 * (p.output.height - 1);
        const ContentUv uv = sample_warp_at(p.warp, p.output, 0.5 * (p.output.width - 1), row);
        const ContentUv left = sample_warp_at(p.warp, p.output, 0.15 * (p.output.width - 1), row);
        const ContentUv right = sample_warp_at(p.warp, p.output, 0.85 * (p.output.width - 1), row);
        if (!uv.valid() || !left.valid() || !right.valid()) continue;
        // As large as fits the middle 70 % of the projector's image, at most 1 font pixel per 135 rows.
        const double span_px = std::abs(static_cast<double>(right.u) - left.u) * content.size.width;
        const int scale =
            std::clamp(static_cast<int>(span_px / std::max(1, widest + 4)), 1, std::max(1, content.size.height / 135));
        const int pad = 2 * scale;
        const int box_w = widest * scale + 2 * pad;
        const int box_h = static_cast<int>(lines.size()) * kGlyphLineHeight * scale + 2 * pad;
        const int cx = static_cast<int>(std::lround(static_cast<double>(uv.u) * content.size.width));
        const int cy = static_cast<int>(std::lround(static_cast<double>(uv.v) * content.size.height));
        const int x0 = std::clamp(cx - box_w / 2, 0, std::max(0, content.size.width - box_w));
        const int y0 = std::clamp(cy - box_h, 0, std::max(0, content.size.height - box_h));
        for (int y = y0; y < std::min(content.size.height, y0 + box_h); ++y) {
            for (int x = x0; x < std::min(content.size.width, x0 + box_w); ++x) {
                std::uint8_t* px = content.at(x, y);
                px[0] = px[1] = px[2] = 16;
            }
        }
        for (std::size_t i = 0; i < lines.size(); ++i) {
            draw_text(content, x0 + pad, y0 + pad + static_cast<int>(i) * kGlyphLineHeight * scale, scale, lines[i],
                      {230, 230, 200});
        }
    }
}

}  // namespace mogao
