// SPDX-License-Identifier: Apache-2.0
// Which connector drives which projector, found from what the camera sees (never from the order in
// which the kernel enumerates connectors), and each connector's EDID identity, so the next run can
// tell whether cables were swapped.
//
// Identification (2 + N images, pattern_budget.h): all outputs black, all white, then each output
// white alone; an output lights the camera pixels whose value rises by more than `min_contrast`.
// The projectors of the site file are listed left to right as the viewer sees them (as in
// rigs/*.toml), and the camera looks at the screen from the viewer's side, so the N outputs that
// light the most pixels, ordered by the centroid x of what they light, are projectors 0..N-1.
// An output lighting fewer than `min_lit_fraction` of the camera's pixels lights nothing: with fewer
// than N lighting outputs the calibration is refused (autocal::CalibrationRefused), naming the
// projector and connector that were expected to light (the camera sees nothing of it).
//
// EDID (VESA E-EDID, release A rev. 2 / EDID 1.4, sec. 3.4 and 3.10.3): bytes 8-9 the
// manufacturer's PNP id (three 5-bit letters), 10-11 the product code (little endian), 12-15 the
// serial number (little endian, 0 = unused), and display descriptors 0xFF (serial number text) and
// 0xFC (product name) among the four 18-byte descriptors at 54. The KMS backend does not read EDID;
// the kernel exposes each connector's blob as /sys/class/drm/card<N>-<connector>/edid.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

namespace mogao::calibrate {

struct EdidIdentity {
    std::string manufacturer;  // PNP id, e.g. "EPS"
    int product = 0;
    std::uint32_t serial = 0;
    std::string serial_text;  // descriptor 0xFF, trimmed; empty when absent
    std::string name;         // descriptor 0xFC, trimmed; empty when absent
};

// nullopt for fewer than 128 bytes or a wrong header (00 FF FF FF FF FF FF 00).
[[nodiscard]] std::optional<EdidIdentity> parse_edid(std::span<const std::uint8_t> edid);

// The EDID of the connector named `connector` (OutputInfo::name) on any card under `sysfs_drm`;
// nullopt when there is none (headless outputs, a projector that sends none).
[[nodiscard]] std::optional<EdidIdentity> read_connector_edid(
    const std::string& connector, const std::filesystem::path& sysfs_drm = "/sys/class/drm");

struct LitOutput {
    std::size_t output = 0;
    double lit_fraction = 0.0;  // of the camera's pixels
    double centroid_x = 0.0;    // camera pixels (NaN when nothing is lit)
};

// What each output lights: `black` = all outputs black, `white[i]` = output i white alone.
[[nodiscard]] std::vector<LitOutput> lit_outputs(const cv::Mat1f& black, const std::vector<cv::Mat1f>& white,
                                                 double min_contrast);

// Projector k -> output index (above). `names[i]` are the outputs' names and `ids[k]` the
// projectors' ids, for the refusal's message. Throws autocal::CalibrationRefused.
[[nodiscard]] std::vector<std::size_t> assign_projectors(const std::vector<LitOutput>& lit,
                                                         const std::vector<std::string>& names,
                                                         const std::vector<std::string>& ids, double min_lit_fraction);

// A cabling change against the previous run's report ("connectors" entries with "projector" and
// "connector"): one line per projector now driven by another connector; empty when the same (or
// no previous report).
[[nodiscard]] std::vector<std::string> cabling_changes(const nlohmann::json& previous, const nlohmann::json& now);

}  // namespace mogao::calibrate
