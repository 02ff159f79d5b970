// SPDX-License-Identifier: Apache-2.0
// Connectors identified by what the camera sees, and their EDID identity (connector_identity.h).
#include "kiosk/calibrate/connector_identity.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>

#include "appliance/autocal/autocal.h"

namespace mogao::calibrate {
namespace {

std::string descriptor_text(std::span<const std::uint8_t> d) {
    std::string s(d.begin() + 5, d.begin() + 18);
    const auto end = s.find_first_of("\n");
    if (end != std::string::npos) s.resize(end);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\0')) s.pop_back();
    return s;
}

}  // namespace

std::optional<EdidIdentity> parse_edid(std::span<const std::uint8_t> e) {
    static constexpr std::uint8_t kHeader[8] = {0x00, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x00};
    if (e.size() < 128 || !std::equal(std::begin(kHeader), std::end(kHeader), e.begin())) return std::nullopt;
    EdidIdentity id;
    const unsigned pnp = (static_cast<unsigned>(e[8]) << 8) | e[9];
    for (const int shift : {10, 5, 0}) id.manufacturer += static_cast<char>('A' - 1 + ((pnp >> shift) & 0x1F));
    id.product = e[10] | (e[11] << 8);
    id.serial = static_cast<std::uint32_t>(e[12]) | static_cast<std::uint32_t>(e[13]) << 8 |
                static_cast<std::uint32_t>(e[14]) << 16 | static_cast<std::uint32_t>(e[15]) << 24;
    for (std::size_t at = 54; at + 18 <= 126; at += 18) {
        const auto d = e.subspan(at, 18);
        if (d[0] != 0 || d[1] != 0) continue;  // a detailed timing, not a display descriptor
        if (d[3] == 0xFF) id.serial_text = descriptor_text(d);
        if (d[3] == 0xFC) id.name = descriptor_text(d);
    }
    return id;
}

std::optional<EdidIdentity> read_connector_edid(const std::string& connector, const std::filesystem::path& sysfs_drm) {
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(sysfs_drm, ec)) {
        const std::string name = entry.path().filename().string();
        const auto dash = name.find('-');
        if (!name.starts_with("card") || dash == std::string::npos || name.substr(dash + 1) != connector) continue;
        std::ifstream f(entry.path() / "edid", std::ios::binary);
        const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
        if (auto id = parse_edid(bytes)) return id;
    }
    return std::nullopt;
}

std::vector<LitOutput> lit_outputs(const cv::Mat1f& black, const std::vector<cv::Mat1f>& white, double min_contrast) {
    std::vector<LitOutput> out;
    for (std::size_t i = 0; i < white.size(); ++i) {
        long lit = 0;
        double sum_x = 0.0;
        for (int y = 0; y < black.rows; ++y) {
            for (int x = 0; x < black.cols; ++x) {
                if (white[i](y, x) - black(y, x) <= min_contrast) continue;
                ++lit;
                sum_x += x + 0.5;
            }
        }
        const double total = static_cast<double>(black.total());
        out.push_back({i, total > 0 ? static_cast<double>(lit) / total : 0.0,
                       lit > 0 ? sum_x / static_cast<double>(lit) : std::numeric_limits<double>::quiet_NaN()});
    }
    return out;
}

std::vector<std::size_t> assign_projectors(const std::vector<LitOutput>& lit, const std::vector<std::string>& names,
                                           const std::vector<std::string>& ids, double min_lit_fraction) {
    std::vector<LitOutput> lighting;
    for (const LitOutput& l : lit) {
        if (l.lit_fraction >= min_lit_fraction) lighting.push_back(l);
    }
    const std::size_t n = ids.size();
    if (lighting.size() < n) {
        // Name the first projector, in connector order, that the camera does not see.
        std::size_t k = 0;
        while (k < lit.size() && k < n && lit[k].lit_fraction >= min_lit_fraction) ++k;
        const std::size_t miss = std::min(k, n - 1);
        const std::string connector = miss < names.size() ? names[miss] : std::string("(none)");
        const double fraction = miss < lit.size() ? lit[miss].lit_fraction : 0.0;
        throw autocal::CalibrationRefused(
            "projector " + std::to_string(miss) + " '" + ids[miss] + "' (connector " + connector +
            "): the camera sees nothing of it: " + std::to_string(lighting.size()) + " of " + std::to_string(n) +
            " outputs light the screen (this one brightens " + std::to_string(100.0 * fraction) +
            " % of the camera's pixels, need " + std::to_string(100.0 * min_lit_fraction) +
            " %); is the projector on, its cable in, the camera looking at the screen and not blocked?");
    }
    std::sort(lighting.begin(), lighting.end(),
              [](const LitOutput& a, const LitOutput& b) { return a.lit_fraction > b.lit_fraction; });
    lighting.resize(n);
    std::sort(lighting.begin(), lighting.end(),
              [](const LitOutput& a, const LitOutput& b) { return a.centroid_x < b.centroid_x; });
    std::vector<std::size_t> out;
    for (const LitOutput& l : lighting) out.push_back(l.output);
    return out;
}

std::vector<std::string> cabling_changes(const nlohmann::json& previous, const nlohmann::json& now) {
    std::vector<std::string> changes;
    if (!previous.is_array()) return changes;
    for (const auto& p : previous) {
        for (const auto& c : now) {
            if (!p.contains("projector") || !c.contains("projector") || p["projector"] != c["projector"]) continue;
            const bool same_edid = !p.contains("edid") || !c.contains("edid") || p["edid"] == c["edid"];
            if (p.value("connector", "") != c.value("connector", "") || !same_edid) {
                changes.push_back("projector '" + c["projector"].get<std::string>() + "' was on connector " +
                                  p.value("connector", "?") + ", is now on " + c.value("connector", "?") +
                                  (same_edid ? "" : " (another EDID: another projector or a swapped cable)"));
            }
        }
    }
    return changes;
}

}  // namespace mogao::calibrate
