// SPDX-License-Identifier: Apache-2.0
// The status page's inputs: the status file and the calibration folder (kiosk_status_page.h).
#include <sys/stat.h>

#include <array>
#include <exception>
#include <string_view>

#include "common/file_io.h"
#include "common/png_io.h"
#include "kiosk/stats/kiosk_status_page.h"

namespace mogao {

namespace fs = std::filesystem;

namespace {

std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

nlohmann::json parse_object(const std::vector<std::uint8_t>& bytes, const fs::path& file, const char* what) {
    if (bytes.empty()) throw StatusPageError(std::string(what) + " " + quoted(file) + " is empty");
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(bytes.begin(), bytes.end());
    } catch (const nlohmann::json::parse_error& e) {
        throw StatusPageError(std::string(what) + " " + quoted(file) + " is not JSON (at byte " +
                              std::to_string(e.byte) + " of " + std::to_string(bytes.size()) + ")");
    }
    if (!j.is_object()) {
        throw StatusPageError(std::string(what) + " " + quoted(file) + " is not a JSON object (found " + j.type_name() +
                              ")");
    }
    return j;
}

std::int64_t mtime_ns(const fs::path& file) {
    struct stat st {};
    if (::stat(file.c_str(), &st) != 0) return 0;
    return static_cast<std::int64_t>(st.st_mtim.tv_sec) * 1'000'000'000 + st.st_mtim.tv_nsec;
}

void read_report(CalibrationFolder& c) {
    const fs::path file = c.dir / "report.json";
    std::error_code ec;
    if (!fs::exists(file, ec)) {
        c.problems.push_back("no report.json in " + quoted(c.dir) + " (no calibration written there yet)");
        return;
    }
    try {
        c.report = parse_object(read_file_bytes(file, kStatusPageMaxReportBytes), file, "calibration report");
        c.report_mtime_ns = mtime_ns(file);
    } catch (const std::exception& e) {
        c.problems.push_back(e.what());
    }
}

// preview.png (mogao-calibrate-sim rig: the screen as a viewer sees it), else camera-white.png
// (mogao-calibrate: what the camera saw with every projector white).
void read_preview(CalibrationFolder& c) {
    for (const char* name : {"preview.png", "camera-white.png"}) {
        const fs::path file = c.dir / name;
        std::error_code ec;
        if (!fs::exists(file, ec)) continue;
        try {
            std::vector<std::uint8_t> bytes = read_file_bytes(file, kStatusPageMaxPreviewBytes);
            const Rgb8Image image = read_png(file);  // a PNG a browser can show, and its size
            c.preview_name = name;
            c.preview_png = std::move(bytes);
            c.preview_width = image.size.width;
            c.preview_height = image.size.height;
            return;
        } catch (const std::exception& e) {
            c.problems.push_back(std::string("preview not shown: ") + e.what());
        }
    }
}

}  // namespace

nlohmann::json read_status_page_status(const fs::path& file) {
    std::vector<std::uint8_t> bytes;
    try {
        bytes = read_file_bytes(file, kStatusPageMaxStatusBytes);
    } catch (const std::exception& e) {
        throw StatusPageError(std::string("status file: ") + e.what());
    }
    nlohmann::json status = parse_object(bytes, file, "status file");
    for (const char* key : {"written_ns", "state", "frames_shown", "calibration"}) {
        if (status.contains(key)) return status;
    }
    throw StatusPageError("status file " + quoted(file) +
                          " is not the kiosk's status file: it has none of written_ns, state, frames_shown, "
                          "calibration (docs/kiosk.md, \"Status file\")");
}

CalibrationFolder read_calibration_folder(const fs::path& dir) {
    CalibrationFolder c;
    c.dir = dir;
    if (dir.empty()) return c;
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) {
        c.problems.push_back("calibration folder " + quoted(dir) + " not found");
        return c;
    }
    read_report(c);
    read_preview(c);
    return c;
}

fs::path calibration_folder_for(const nlohmann::json& status, const fs::path& dir) {
    if (!dir.empty()) return dir;
    const auto cal = status.find("calibration");
    if (cal == status.end() || !cal->is_object()) return {};
    const auto source = cal->find("source");
    if (source == cal->end() || !source->is_string()) return {};
    const fs::path file = source->get<std::string>();
    std::error_code ec;
    if (file.empty() || !fs::is_regular_file(file, ec)) return {};  // "ideal", "selfcal", a file gone
    const fs::path folder = file.parent_path().empty() ? fs::path(".") : file.parent_path();
    return fs::exists(folder / "report.json", ec) ? folder : fs::path{};
}

std::string base64_encode(const std::vector<std::uint8_t>& bytes) {
    static constexpr std::string_view kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    std::size_t i = 0;
    for (; i + 2 < bytes.size(); i += 3) {
        const std::uint32_t v = (std::uint32_t{bytes[i]} << 16) | (std::uint32_t{bytes[i + 1]} << 8) | bytes[i + 2];
        for (const int shift : {18, 12, 6, 0}) out.push_back(kAlphabet[(v >> shift) & 63u]);
    }
    if (i < bytes.size()) {
        const bool two = i + 1 < bytes.size();
        const std::uint32_t v = (std::uint32_t{bytes[i]} << 16) | (two ? std::uint32_t{bytes[i + 1]} << 8 : 0u);
        out.push_back(kAlphabet[(v >> 18) & 63u]);
        out.push_back(kAlphabet[(v >> 12) & 63u]);
        out.push_back(two ? kAlphabet[(v >> 6) & 63u] : '=');
        out.push_back('=');
    }
    return out;
}

std::string html_escape(const std::string& text) {
    std::string out;
    out.reserve(text.size());
    for (const char ch : text) {
        switch (ch) {
            case '&':
                out += "&amp;";
                break;
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '"':
                out += "&quot;";
                break;
            case '\'':
                out += "&#39;";
                break;
            default:
                if (static_cast<unsigned char>(ch) >= 0x20 && ch != 0x7f) out.push_back(ch);
        }
    }
    return out;
}

}  // namespace mogao
