// SPDX-License-Identifier: Apache-2.0
// The technician's status page (docs/monitoring.md, "Status page"): one self-contained HTML file
// made from the kiosk's status file (kiosk_status.h; schema in docs/kiosk.md, "Status file") and,
// optionally, the calibration's output folder (`mogao-calibrate --out`, `mogao-calibrate-sim rig
// --out`: report.json, preview.png or camera-white.png). It shows the kiosk's state and the time
// of the status, the link, the frames shown, the frame rate, motion-to-photon latency (mean, p95),
// the calibration on the wall with its preview image, the self-check figure (on-site accuracy in
// projector pixels: report.json's self_check.mean_px / p95_px against its gate) and the latest
// refused calibration update, and each certificate's notAfter.
//
// The file holds everything: inline CSS, the preview as a data: URI (base64 PNG), no JavaScript,
// no reference to anything outside it, so it opens from a USB stick in any browser, offline.
// Every value comes from the files; a value that is absent or of the wrong type shows as
// "unknown" (never a default, a zero or a raw dump), every text is HTML-escaped.
//
// Units: times in the status file are CLOCK_REALTIME ns ("*_ns") or ISO 8601 UTC ("*_utc"), shown
// as the UTC text; latency in ms, rates in frames per second, the self-check in projector pixels.
// Errors: read_status_page_status throws StatusPageError naming the status file and what is wrong
// with it (missing, unreadable, too large, not JSON, not an object). A calibration folder that is
// missing or has a garbled report or preview does not stop the page: the page says what is wrong
// with which file.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace mogao {

class StatusPageError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Limits on what is read: a status file is a few KiB, a report tens of KiB, a preview PNG a few
// hundred KiB (preview.png is 960 pixels wide).
inline constexpr std::uint64_t kStatusPageMaxStatusBytes = 1u << 20;   // 1 MiB
inline constexpr std::uint64_t kStatusPageMaxReportBytes = 8u << 20;   // 8 MiB
inline constexpr std::uint64_t kStatusPageMaxPreviewBytes = 8u << 20;  // 8 MiB

// What the calibration folder holds, as far as the page shows it.
struct CalibrationFolder {
    std::filesystem::path dir;              // empty: none given
    std::optional<nlohmann::json> report;   // report.json, when it parsed as a JSON object
    std::int64_t report_mtime_ns = 0;       // report.json's modification time (CLOCK_REALTIME)
    std::string preview_name;               // "preview.png" or "camera-white.png"; empty: none
    std::vector<std::uint8_t> preview_png;  // its bytes (a PNG that decoded), embedded as a data: URI
    int preview_width = 0;                  // its pixels
    int preview_height = 0;
    std::vector<std::string> problems;  // what could not be used, each naming its file
};

struct StatusPageInput {
    std::filesystem::path status_file;  // shown on the page
    nlohmann::json status;              // the status file's object
    CalibrationFolder calibration;
    std::int64_t made_ns = 0;  // when the page is made (CLOCK_REALTIME), for the status's age
};

// Reads and parses the status file. Throws StatusPageError naming `file`.
[[nodiscard]] nlohmann::json read_status_page_status(const std::filesystem::path& file);

// Reads `dir`'s report.json and its preview (preview.png, else camera-white.png). Never throws for
// the folder's content: what is missing or bad is listed in `problems`.
[[nodiscard]] CalibrationFolder read_calibration_folder(const std::filesystem::path& dir);

// The calibration folder for a status: `dir` when given, else the folder of the status's
// calibration.source when that is a file beside a report.json (a calibration used straight from
// its output folder), else none (empty path).
[[nodiscard]] std::filesystem::path calibration_folder_for(const nlohmann::json& status,
                                                           const std::filesystem::path& dir);

// The page. Pure.
[[nodiscard]] std::string kiosk_status_page_html(const StatusPageInput& input);

// Standard base64 (RFC 4648, with padding), for the data: URI.
[[nodiscard]] std::string base64_encode(const std::vector<std::uint8_t>& bytes);

// "&", "<", ">", '"' and "'" as entities, control characters dropped.
[[nodiscard]] std::string html_escape(const std::string& text);

}  // namespace mogao
