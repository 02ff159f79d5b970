// SPDX-License-Identifier: Apache-2.0
// The status page's HTML (kiosk_status_page.h): values read from the status file's JSON by path and
// type; anything else shows as "unknown".
#include "kiosk/stats/kiosk_status_page.h"

#include <cmath>
#include <initializer_list>
#include <iterator>

#include <fmt/format.h>

#include "kiosk/stats/kiosk_status.h"

namespace mogao {

namespace {

using nlohmann::json;

// Seconds a running kiosk's status may be old before the page flags it (the metrics' stale alert).
constexpr double kStaleAfterS = 30.0;

const json* find(const json& j, std::initializer_list<const char*> path) {
    const json* at = &j;
    for (const char* key : path) {
        if (!at->is_object()) return nullptr;
        const auto it = at->find(key);
        if (it == at->end()) return nullptr;
        at = &*it;
    }
    return at;
}

std::optional<double> number(const json& j, std::initializer_list<const char*> path) {
    const json* v = find(j, path);
    if (v == nullptr || !v->is_number()) return std::nullopt;
    const double d = v->get<double>();
    return std::isfinite(d) ? std::optional(d) : std::nullopt;
}

std::optional<std::uint64_t> count(const json& j, std::initializer_list<const char*> path) {
    const json* v = find(j, path);
    if (v == nullptr) return std::nullopt;
    if (v->is_number_unsigned()) return v->get<std::uint64_t>();
    if (v->is_number_integer() && v->get<std::int64_t>() >= 0) return v->get<std::uint64_t>();
    return std::nullopt;
}

std::optional<std::string> text(const json& j, std::initializer_list<const char*> path) {
    const json* v = find(j, path);
    if (v == nullptr || !v->is_string()) return std::nullopt;
    return v->get<std::string>();
}

std::optional<bool> flag(const json& j, std::initializer_list<const char*> path) {
    const json* v = find(j, path);
    if (v == nullptr || !v->is_boolean()) return std::nullopt;
    return v->get<bool>();
}

const std::string kUnknown = R"(<span class="unknown">unknown</span>)";

std::string esc_or_unknown(const std::optional<std::string>& s) {
    return s && !s->empty() ? html_escape(*s) : kUnknown;
}

std::string fixed(const std::optional<double>& v, int decimals, const char* unit) {
    if (!v) return kUnknown;
    return fmt::format("{:.{}f}{}", *v, decimals, unit);
}

std::string duration_text(double s) {
    if (s < 0) return fmt::format("{:.0f} s", s);
    const auto whole = static_cast<std::int64_t>(s);
    if (whole >= 86'400)
        return fmt::format("{} d {} h {:02} min", whole / 86'400, whole % 86'400 / 3600, whole % 3600 / 60);
    if (whole >= 3600) return fmt::format("{} h {:02} min {:02} s", whole / 3600, whole % 3600 / 60, whole % 60);
    if (whole >= 60) return fmt::format("{} min {:02} s", whole / 60, whole % 60);
    return fmt::format("{:.1f} s", s);
}

void row(std::string& out, const char* label, const char* id, const std::string& value_html) {
    fmt::format_to(std::back_inserter(out), "<tr><th>{}</th><td id=\"{}\">{}</td></tr>\n", label, id, value_html);
}

void note(std::string& out, const char* kind, const std::string& html) {
    fmt::format_to(std::back_inserter(out), "<p class=\"{}\">{}</p>\n", kind, html);
}

// The state word as a coloured badge; an unknown word shows escaped in the neutral colour.
std::string state_badge(const std::optional<std::string>& state) {
    if (!state) return std::string(R"(<span class="badge b-unknown" id="state">unknown</span>)");
    std::string kind = "unknown";
    for (const char* known : {"showing", "connecting", "disconnected", "stopped"}) {
        if (*state == known) kind = known;
    }
    return fmt::format(R"(<span class="badge b-{}" id="state">{}</span>)", kind, html_escape(*state));
}

void header(std::string& out, const StatusPageInput& in) {
    const json& s = in.status;
    const auto state = text(s, {"state"});
    fmt::format_to(std::back_inserter(out), "<header><h1>Kiosk status {}</h1>\n", state_badge(state));
    auto written = text(s, {"written_utc"});
    const auto written_ns = number(s, {"written_ns"});
    if (!written && written_ns) written = utc_text(static_cast<std::int64_t>(*written_ns));
    std::string age = kUnknown;
    std::optional<double> age_s;
    if (written_ns && in.made_ns > 0) {
        age_s = (static_cast<double>(in.made_ns) - *written_ns) / 1e9;
        age = *age_s >= 0 ? duration_text(*age_s) + " before this page was made"
                          : duration_text(-*age_s) + " after this page was made (clocks differ)";
    }
    fmt::format_to(std::back_inserter(out),
                   "<p class=\"when\">Status written <b id=\"written\">{}</b> (<span id=\"age\">{}</span>); page made "
                   "{}</p>\n",
                   esc_or_unknown(written), age, in.made_ns > 0 ? utc_text(in.made_ns) : kUnknown);
    if (age_s && *age_s > kStaleAfterS && state != "stopped") {
        note(out, "warn",
             fmt::format("This status is {} old: a running kiosk rewrites it every second or so. The kiosk may "
                         "have stopped or hang.",
                         duration_text(*age_s)));
    }
    out += "</header>\n";
}

void show_section(std::string& out, const json& s) {
    out += "<section id=\"show\"><h2>Picture</h2><table>\n";
    const auto frames = count(s, {"frames_shown"});
    row(out, "Frames shown", "frames-shown", frames ? fmt::format("{}", *frames) : kUnknown);
    // fps and latency are 0 until two frames were shown (kiosk_stats.h's window): no figure yet.
    const bool measured = frames && *frames >= 2;
    const std::string none_yet = R"(<span class="unknown">none yet (fewer than two frames)</span>)";
    const auto fps = number(s, {"fps"});
    row(out, "Frame rate", "fps", fps && !measured ? none_yet : fixed(fps, 1, " frames/s"));
    const auto mean = number(s, {"latency_mean_ms"});
    const auto p95 = number(s, {"latency_p95_ms"});
    row(out, "Motion-to-photon, mean", "latency-mean", mean && !measured ? none_yet : fixed(mean, 1, " ms"));
    row(out, "Motion-to-photon, p95", "latency-p95", p95 && !measured ? none_yet : fixed(p95, 1, " ms"));
    const auto uptime = number(s, {"uptime_s"});
    row(out, "Kiosk running for", "uptime", uptime ? duration_text(*uptime) : kUnknown);
    const auto request = count(s, {"showing_request"});
    row(out, "Request on the wall", "showing-request",
        !request        ? kUnknown
        : *request == 0 ? std::string("0 (the connecting screen)")
                        : fmt::format("{}", *request));
    out += "</table></section>\n";
}

void link_section(std::string& out, const json& s) {
    out += "<section id=\"link\"><h2>Farm link</h2><table>\n";
    const auto connected = flag(s, {"farm", "connected"});
    row(out, "Connected", "farm-connected",
        !connected   ? kUnknown
        : *connected ? std::string(R"(<span class="ok">yes</span>)")
                     : std::string(R"(<span class="bad">no</span>)"));
    row(out, "Farm", "farm-endpoint", esc_or_unknown(text(s, {"farm", "endpoint"})));
    const auto silent = number(s, {"farm", "silent_s"});
    row(out, "Since the last farm frame", "farm-silent", silent ? duration_text(*silent) : kUnknown);
    const json* err = find(s, {"last_error"});
    std::string last = kUnknown;
    if (err != nullptr && err->is_null()) last = "none since start";
    if (err != nullptr && err->is_object()) {
        last = esc_or_unknown(text(*err, {"what"})) + " <span class=\"small\">(" + esc_or_unknown(text(*err, {"utc"})) +
               ")</span>";
    }
    row(out, "Latest error", "last-error", last);
    out += "</table></section>\n";
}

void certificates_section(std::string& out, const json& s) {
    out += "<section id=\"certificates\"><h2>Certificates</h2>\n";
    const json* certs = find(s, {"certificates"});
    if (certs == nullptr || !certs->is_array()) {
        out += "<p id=\"certificates-none\">" + kUnknown + "</p></section>\n";
        return;
    }
    if (certs->empty()) {
        out += "<p id=\"certificates-none\">none reported (the link holds no certificate yet)</p></section>\n";
        return;
    }
    out += "<table class=\"list\"><tr><th>role</th><th>name</th><th>not after (UTC)</th><th>days left</th></tr>\n";
    int k = 0;
    for (const json& c : *certs) {
        auto not_after = text(c, {"not_after_utc"});
        if (!not_after) {
            if (const auto sec = number(c, {"not_after_s"}))
                not_after = utc_text(static_cast<std::int64_t>(*sec) * 1'000'000'000);
        }
        const auto days = number(c, {"days_left"});
        const bool soon = flag(c, {"expires_soon"}).value_or(false);
        fmt::format_to(std::back_inserter(out),
                       "<tr{}><td>{}</td><td>{}</td><td id=\"cert-{}-not-after\">{}</td><td>{}{}</td></tr>\n",
                       soon ? " class=\"warnrow\"" : "", esc_or_unknown(text(c, {"role"})),
                       esc_or_unknown(text(c, {"name"})), k, esc_or_unknown(not_after), fixed(days, 0, ""),
                       soon ? " (renew it)" : "");
        ++k;
    }
    out += "</table></section>\n";
}

void wall_section(std::string& out, const json& s) {
    out += "<section id=\"wall\"><h2>On the wall</h2>\n";
    const json* lines = find(s, {"on_wall"});
    if (lines == nullptr || !lines->is_array()) {
        out += "<p id=\"on-wall\">" + kUnknown + "</p>\n";
    } else if (lines->empty()) {
        out += "<p id=\"on-wall\">the picture alone (no text drawn over it)</p>\n";
    } else {
        out += "<ul id=\"on-wall\">";
        for (const json& l : *lines)
            out += "<li>" + (l.is_string() ? html_escape(l.get<std::string>()) : kUnknown) + "</li>";
        out += "</ul>\n";
    }
    const json* fallbacks = find(s, {"fallbacks"});
    if (fallbacks != nullptr && fallbacks->is_array() && !fallbacks->empty()) {
        out += "<p class=\"warn\">Started from last good copies:</p><ul id=\"fallbacks\">";
        for (const json& f : *fallbacks)
            out += "<li>" + (f.is_string() ? html_escape(f.get<std::string>()) : kUnknown) + "</li>";
        out += "</ul>\n";
    }
    out += "</section>\n";
}

void calibration_rows(std::string& out, const json& s) {
    row(out, "On the wall", "calibration-source", esc_or_unknown(text(s, {"calibration", "source"})));
    row(out, "Loaded", "calibration-loaded", esc_or_unknown(text(s, {"calibration", "loaded_utc"})));
    const auto swaps = count(s, {"calibration", "swaps"});
    const auto refused = count(s, {"calibration", "refused"});
    row(out, "Swapped in since start", "calibration-swaps", swaps ? fmt::format("{}", *swaps) : kUnknown);
    row(out, "Updates refused since start", "calibration-refused",
        refused ? fmt::format("<span class=\"{}\">{}</span>", *refused > 0 ? "bad" : "ok", *refused) : kUnknown);
    const auto reason = text(s, {"calibration", "last_error"});
    std::string refusal = kUnknown;
    if (reason && reason->empty()) refusal = "none since it was loaded";
    if (reason && !reason->empty()) {
        refusal = "<span class=\"bad\">" + html_escape(*reason) + "</span> <span class=\"small\">(" +
                  esc_or_unknown(text(s, {"calibration", "last_error_utc"})) +
                  "; the calibration above was kept)</span>";
    }
    row(out, "Latest refused update", "calibration-refusal", refusal);
    const auto selfcal = flag(s, {"selfcal", "enabled"});
    std::string sc = kUnknown;
    if (selfcal && !*selfcal) sc = "off";
    if (selfcal && *selfcal) {
        sc = esc_or_unknown(text(s, {"selfcal", "state"}));
        if (const auto line = text(s, {"selfcal", "line"}))
            sc += "<br><span class=\"small\">" + html_escape(*line) + "</span>";
    }
    row(out, "Self-recalibration", "selfcal", sc);
}

// report.json's self_check: the on-site accuracy figure (projector pixels), against its gate.
void self_check_rows(std::string& out, const CalibrationFolder& c) {
    const json* check = c.report ? find(*c.report, {"self_check"}) : nullptr;
    std::string why;
    if (c.dir.empty()) {
        why = "no calibration folder given";
    } else if (!c.report) {
        why = "no readable report.json";
    } else if (check == nullptr) {
        why = "report.json has none: a calibration from captured images has no self-check";
    }
    const std::string reason = why.empty() ? "" : " <span class=\"small\">(" + html_escape(why) + ")</span>";
    const auto mean = check ? number(*check, {"mean_px"}) : std::nullopt;
    const auto p95 = check ? number(*check, {"p95_px"}) : std::nullopt;
    const auto gate = check ? number(*check, {"gate_max_mean_px"}) : std::nullopt;
    const auto mm = check ? number(*check, {"mean_mm"}) : std::nullopt;
    row(out, "Self-check, mean", "self-check-mean",
        fixed(mean, 3, " px") +
            (mm ? fmt::format(" <span class=\"small\">({:.2f} mm on the screen)</span>", *mm) : "") + reason);
    row(out, "Self-check, p95", "self-check-p95", fixed(p95, 3, " px"));
    std::string verdict = fixed(gate, 2, " px mean");
    if (gate && mean)
        verdict += *mean <= *gate ? R"( <span class="ok">(passed)</span>)" : R"( <span class="bad">(above)</span>)";
    row(out, "Self-check gate", "self-check-gate", verdict);
    std::string when = kUnknown;
    if (c.report) when = c.report_mtime_ns > 0 ? "report.json of " + utc_text(c.report_mtime_ns) : "report.json";
    row(out, "Calibration run", "calibration-report", when);
}

void preview_figure(std::string& out, const CalibrationFolder& c) {
    if (c.preview_png.empty()) {
        out += "<p id=\"preview-none\" class=\"info\">No preview image (";
        out += c.dir.empty() ? "no calibration folder given" : "no preview.png or camera-white.png in the folder";
        out += ").</p>\n";
        return;
    }
    const bool viewer = c.preview_name == "preview.png";
    fmt::format_to(std::back_inserter(out),
                   "<figure><img id=\"preview\" width=\"{}\" height=\"{}\" alt=\"{}\" "
                   "src=\"data:image/png;base64,{}\"><figcaption>{} ({}&#215;{}): {}</figcaption></figure>\n",
                   c.preview_width, c.preview_height, html_escape(c.preview_name), base64_encode(c.preview_png),
                   html_escape(c.preview_name), c.preview_width, c.preview_height,
                   viewer ? "the screen as a viewer sees it through this calibration"
                          : "what the calibration camera saw with every projector white");
}

void calibration_section(std::string& out, const StatusPageInput& in) {
    out += "<section id=\"calibration\"><h2>Calibration</h2><table>\n";
    calibration_rows(out, in.status);
    self_check_rows(out, in.calibration);
    out += "</table>\n";
    for (const std::string& p : in.calibration.problems) note(out, "info", html_escape(p));
    preview_figure(out, in.calibration);
    out += "</section>\n";
}

const char* const kStyle = R"(
body{font-family:"DejaVu Sans",Arial,Helvetica,sans-serif;font-size:15px;color:#1d232b;background:#eef0f3;
margin:0;padding:18px 22px}
header{margin-bottom:12px}h1{font-size:24px;margin:0 0 4px 0}h2{font-size:17px;margin:0 0 8px 0;color:#2b4a6f}
.when{margin:2px 0;color:#3a4450}.grid{display:grid;grid-template-columns:1fr 1.15fr;gap:14px;align-items:start}
section{background:#fff;border:1px solid #cfd5dc;border-radius:6px;padding:10px 14px;margin-bottom:14px}
table{border-collapse:collapse;width:100%}th,td{text-align:left;padding:3px 8px 3px 0;vertical-align:top}
th{font-weight:normal;color:#55606c;width:46%}td{font-weight:bold}table.list th{width:auto;font-size:13px}
table.list td{font-weight:normal;font-size:14px}.unknown{color:#8a939c;font-style:italic;font-weight:normal}
.badge{font-size:15px;padding:3px 10px;border-radius:12px;color:#fff;vertical-align:middle;margin-left:8px}
.b-showing{background:#23864a}.b-connecting{background:#b7791f}.b-disconnected{background:#c0392b}
.b-stopped{background:#5d6670}.b-unknown{background:#8a939c}.ok{color:#23864a}.bad{color:#c0392b}
.warn{background:#fdecea;border-left:4px solid #c0392b;padding:5px 8px;margin:6px 0}.warnrow td{color:#c0392b}
.info{color:#55606c;font-size:13px;margin:4px 0}.small{font-size:12px;font-weight:normal;color:#55606c}
figure{margin:8px 0 0 0}
figure img{max-width:100%;height:auto;border:1px solid #cfd5dc;background:#000;image-rendering:auto}
figcaption{font-size:12px;color:#55606c}footer{font-size:12px;color:#55606c}ul{margin:4px 0;padding-left:20px}
)";

}  // namespace

std::string kiosk_status_page_html(const StatusPageInput& in) {
    std::string out;
    out.reserve(8192 + in.calibration.preview_png.size() * 4 / 3);
    out += "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>mogao kiosk status";
    if (const auto w = text(in.status, {"written_utc"})) out += " " + html_escape(*w);
    out += "</title>\n<style>";
    out += kStyle;
    out += "</style></head>\n<body>\n";
    header(out, in);
    out += "<div class=\"grid\"><div>\n";
    show_section(out, in.status);
    link_section(out, in.status);
    certificates_section(out, in.status);
    wall_section(out, in.status);
    out += "</div><div>\n";
    calibration_section(out, in);
    out += "</div></div>\n";
    fmt::format_to(std::back_inserter(out),
                   "<footer>From the status file <span id=\"status-file\">{}</span>{}. mogao-kiosk-status-page; "
                   "docs/monitoring.md, \"Status page\".</footer>\n</body></html>\n",
                   html_escape(in.status_file.filename().string()),
                   in.calibration.dir.empty()
                       ? std::string()
                       : " and the calibration folder " + html_escape(in.calibration.dir.string()));
    return out;
}

}  // namespace mogao
