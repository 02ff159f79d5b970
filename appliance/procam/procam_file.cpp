// SPDX-License-Identifier: Apache-2.0
// The procam calibration file: writer and the projector prior's reader (procam_calibration.h).
#include <fstream>
#include <sstream>
#include <string>

#include "appliance/procam/procam_calibration.h"
#include "appliance/procam/procam_error.h"
#include "common/file_io.h"

namespace mogao::procam {

namespace {

constexpr const char* kFormat = "mogao-procam 1";

nlohmann::json intrinsics_json(const Intrinsics& i) {
    nlohmann::json k = nlohmann::json::array();
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) k.push_back(i.K(r, c));
    }
    return {{"size", {i.size.width, i.size.height}}, {"K", k}, {"dist", i.dist}};
}

// Reads field `key` of `j` (named `where` in messages) as a number.
double number_at(const nlohmann::json& j, std::size_t index, const std::string& file, const std::string& where) {
    if (!j.is_array() || index >= j.size() || !j[index].is_number()) {
        throw ProcamError(file + ": " + where + "[" + std::to_string(index) + "] must be a number");
    }
    const double v = j[index].get<double>();
    if (!std::isfinite(v)) throw ProcamError(file + ": " + where + "[" + std::to_string(index) + "] must be finite");
    return v;
}

const nlohmann::json& field(const nlohmann::json& j, const char* key, const std::string& file, const std::string& where,
                            std::size_t length) {
    if (!j.is_object() || !j.contains(key) || !j[key].is_array() || j[key].size() != length) {
        throw ProcamError(file + ": " + where + "." + key + " must be an array of " + std::to_string(length) +
                          " numbers");
    }
    return j[key];
}

}  // namespace

nlohmann::json procam_json(const ProcamCalibration& c, const std::vector<HeldOutError>& held_out) {
    nlohmann::json r = nlohmann::json::array();
    for (int i = 0; i < 3; ++i) {
        for (int k = 0; k < 3; ++k) r.push_back(c.R(i, k));
    }
    nlohmann::json captures = nlohmann::json::array();
    for (const CaptureResidual& p : c.captures) {
        captures.push_back({{"name", p.name},
                            {"corners", p.corners},
                            {"camera_rms_px", p.camera_rms_px},
                            {"projector_rms_px", p.projector_rms_px}});
    }
    nlohmann::json j = {{"format", kFormat},
                        {"camera", intrinsics_json(c.camera)},
                        {"projector", intrinsics_json(c.projector)},
                        {"R", r},
                        {"T", {c.T[0], c.T[1], c.T[2]}},
                        {"units", "mm"},
                        {"rms", c.rms},
                        {"camera_rms", c.camera_rms},
                        {"projector_rms", c.projector_rms},
                        {"captures", captures}};
    if (!held_out.empty()) {
        nlohmann::json h = nlohmann::json::array();
        for (const HeldOutError& e : held_out) {
            h.push_back({{"name", e.name},
                         {"corners", e.corners},
                         {"mean_px", e.mean_px},
                         {"p95_px", e.p95_px},
                         {"max_px", e.max_px}});
        }
        j["held_out"] = h;
    }
    return j;
}

void write_procam_file(const std::filesystem::path& path, const nlohmann::json& j) {
    const std::string text = j.dump(2) + "\n";
    write_file_atomically(path, std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

Intrinsics read_procam_projector(const std::filesystem::path& path) {
    const std::string file = path.string();
    std::ifstream in(path);
    if (!in) throw ProcamError(file + ": cannot be read");
    std::stringstream text;
    text << in.rdbuf();
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(text.str());
    } catch (const nlohmann::json::exception& e) {
        throw ProcamError(file + ": not JSON: " + e.what());
    }
    if (!j.is_object() || !j.contains("format") || j["format"] != kFormat) {
        throw ProcamError(file + ": format must be \"" + kFormat + "\"");
    }
    if (!j.contains("projector")) throw ProcamError(file + ": projector is missing");
    const nlohmann::json& p = j["projector"];
    Intrinsics out;
    const nlohmann::json& size = field(p, "size", file, "projector", 2);
    const double w = number_at(size, 0, file, "projector.size");
    const double h = number_at(size, 1, file, "projector.size");
    if (w < 2 || h < 2 || w > 16384 || h > 16384 || w != std::floor(w) || h != std::floor(h)) {
        throw ProcamError(file + ": projector.size must be two whole numbers within 2..16384");
    }
    out.size = ImageSize{static_cast<int>(w), static_cast<int>(h)};
    const nlohmann::json& k = field(p, "K", file, "projector", 9);
    for (int i = 0; i < 9; ++i) out.K.val[i] = number_at(k, static_cast<std::size_t>(i), file, "projector.K");
    if (!(out.K(0, 0) > 0 && out.K(1, 1) > 0)) throw ProcamError(file + ": projector.K: fx and fy must be > 0");
    if (out.K(0, 2) < 0 || out.K(0, 2) > w || out.K(1, 2) < 0 || out.K(1, 2) > h) {
        throw ProcamError(file + ": projector.K: the principal point must lie in the image");
    }
    const nlohmann::json& d = field(p, "dist", file, "projector", 5);
    for (std::size_t i = 0; i < 5; ++i) out.dist[i] = number_at(d, i, file, "projector.dist");
    return out;
}

}  // namespace mogao::procam
