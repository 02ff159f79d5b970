// SPDX-License-Identifier: Apache-2.0
// The models file beside the MPCDI (model_store.h): JSON writer and validating reader.
#include "appliance/autocal/model_store.h"

#include <cmath>
#include <span>

#include <Eigen/LU>
#include <fmt/format.h>

#include "appliance/rig/rig_model.h"
#include "common/file_io.h"

namespace mogao::autocal {
namespace {

constexpr const char* kFormat = "mogao-calibration-models";
constexpr int kVersion = 1;
constexpr int kMaxSide = 16384;
constexpr int kMaxProjectors = 64;

using Json = nlohmann::json;

// Field access with messages "<file>: <path> ...": every getter checks type and range.
class Reader {
public:
    Reader(std::string file, const Json& json, std::string path)
        : file_(std::move(file)), json_(json), path_(std::move(path)) {}

    [[noreturn]] void fail(const std::string& field, const std::string& what) const {
        throw ModelStoreError(fmt::format("{}: {}{}", file_, join(field), what));
    }

    [[nodiscard]] std::string join(const std::string& field) const {
        if (path_.empty()) return field;
        if (field.empty()) return path_;
        return field.front() == '[' ? path_ + field : path_ + "." + field;
    }

    [[nodiscard]] const Json& at(const std::string& key) const {
        if (!json_.is_object()) fail("", " must be a JSON object");
        const auto it = json_.find(key);
        if (it == json_.end()) fail(key, " is missing");
        return *it;
    }

    [[nodiscard]] Reader child(const std::string& key) const { return {file_, at(key), join(key)}; }

    [[nodiscard]] double number(const std::string& key, double lo, double hi, const char* range) const {
        return number_of(at(key), key, lo, hi, range);
    }

    [[nodiscard]] double number_of(const Json& v, const std::string& field, double lo, double hi,
                                   const char* range) const {
        if (!v.is_number()) fail(field, fmt::format(" must be a number, got {}", v.dump()));
        const double x = v.get<double>();
        if (!std::isfinite(x) || x < lo || x > hi) fail(field, fmt::format(" = {} is outside {}", x, range));
        return x;
    }

    // An array of exactly n numbers within [lo, hi].
    [[nodiscard]] std::vector<double> numbers(const std::string& key, std::size_t n, double lo, double hi,
                                              const char* range) const {
        const Json& v = at(key);
        if (!v.is_array() || v.size() != n) fail(key, fmt::format(" must be an array of {} numbers", n));
        std::vector<double> out;
        for (std::size_t i = 0; i < n; ++i)
            out.push_back(number_of(v[i], fmt::format("{}[{}]", key, i), lo, hi, range));
        return out;
    }

    [[nodiscard]] const Json& json() const { return json_; }
    [[nodiscard]] const std::string& file() const { return file_; }

private:
    std::string file_;
    const Json& json_;
    std::string path_;
};

constexpr double kBig = 1e6;

ScreenModel read_screen(const Reader& r) {
    ScreenModel s;
    s.radius_m = r.number("radius_m", 1e-3, 1e3, "(0, 1000] m");
    s.arc_deg = r.number("arc_deg", 1e-3, 360.0, "(0, 360] degrees");
    s.bottom_m = r.number("bottom_m", -1e3, 1e3, "[-1000, 1000] m");
    s.top_m = r.number("top_m", -1e3, 1e3, "[-1000, 1000] m");
    if (!(s.top_m > s.bottom_m)) r.fail("top_m", fmt::format(" = {} must be above bottom_m = {}", s.top_m, s.bottom_m));
    // Optional (files before the bow was fitted have none: a cylinder); each mode within 10 % of the radius.
    if (r.json().is_object() && r.json().contains("bow_m")) {
        const double limit = 0.1 * s.radius_m;
        const std::vector<double> bow = r.numbers("bow_m", s.bow_m.size(), -limit, limit, "[-0.1, 0.1] x radius_m");
        std::copy(bow.begin(), bow.end(), s.bow_m.begin());
    }
    // Optional (files from before gain screens were modelled have none: a matte screen, viewed from the axis).
    if (r.json().is_object() && r.json().contains("gain")) {
        s.gain = r.number("gain", 1.0, 3.0, "[1, 3]");
        s.half_gain_angle_deg = r.number("half_gain_angle_deg", 10.0, 90.0, "[10, 90] degrees");
        const std::vector<double> v = r.numbers("viewer_m", 3, -1e3, 1e3, "[-1000, 1000] m");
        s.viewer_m = {v[0], v[1], v[2]};
    }
    // Optional (files from before the screen's own light was measured have none: no indirect light).
    if (r.json().is_object() && r.json().contains("interreflection"))
        s.interreflection = r.number("interreflection", 0.0, 0.99, "[0, 0.99]");
    return s;
}

Eigen::Matrix3d read_rotation(const Reader& r) {
    const Json& v = r.at("rotation");
    if (!v.is_array() || v.size() != 3) r.fail("rotation", " must be 3 rows of 3 numbers");
    Eigen::Matrix3d m;
    for (int i = 0; i < 3; ++i) {
        const Json& row = v[static_cast<std::size_t>(i)];
        if (!row.is_array() || row.size() != 3) r.fail(fmt::format("rotation[{}]", i), " must be 3 numbers");
        for (int j = 0; j < 3; ++j) {
            m(i, j) = r.number_of(row[static_cast<std::size_t>(j)], fmt::format("rotation[{}][{}]", i, j), -1.0 - 1e-6,
                                  1.0 + 1e-6, "[-1, 1]");
        }
    }
    const double orthogonality = (m.transpose() * m - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (orthogonality > 1e-6) {
        r.fail("rotation", fmt::format(" is not orthonormal: max |R^T R - I| = {:.3g} > 1e-6", orthogonality));
    }
    if (m.determinant() < 0.0) r.fail("rotation", " is a reflection (determinant -1), not a rotation");
    return m;
}

// A projector's lens distortion as the calibration's trial fits it: within a projection lens's coefficients
// (rig::kProjectorDistortionLimits) and one-to-one out to 1.2 times the normalised radius of the image's
// farthest corner (rig::distortion_fold_radius), so that each image position has one ray (warps and
// self-recalibration invert it).
void check_projector_distortion(const Reader& r, const DeviceModel& d) {
    const auto& k = d.distortion;
    const auto& limit = rig::kProjectorDistortionLimits;
    for (std::size_t i = 0; i < k.size(); ++i) {
        if (!(std::abs(k[i]) <= limit[i])) {
            r.fail(fmt::format("distortion[{}]", i),
                   fmt::format(" = {} is outside [-{}, {}] (a projection lens's)", k[i], limit[i], limit[i]));
        }
    }
    double corner2 = 0.0;
    for (const double x : {0.0, double(d.resolution.width)})
        for (const double y : {0.0, double(d.resolution.height)})
            corner2 = std::max(corner2, std::pow((x - d.cx_px) / d.fx_px, 2) + std::pow((y - d.cy_px) / d.fy_px, 2));
    if (const std::optional<double> fold = rig::distortion_fold_radius(k, 1.2 * std::sqrt(corner2))) {
        r.fail("distortion", fmt::format(" is not one-to-one out to 1.2 times the image's corners (d/dr of "
                                         "r (1 + k1 r^2 + k2 r^4 + k3 r^6) <= 0 at r = {:.4g})",
                                         *fold));
    }
}

DeviceModel read_device(const Reader& r, bool camera) {
    DeviceModel d;
    const Json& id = r.at("id");
    if (!id.is_string() || id.get<std::string>().empty() || id.get<std::string>().size() > 256) {
        r.fail("id", " must be a non-empty string of at most 256 characters");
    }
    d.id = id.get<std::string>();
    const std::vector<double> res = r.numbers("resolution", 2, 1, kMaxSide, "[1, 16384] px");
    if (res[0] != std::floor(res[0]) || res[1] != std::floor(res[1])) r.fail("resolution", " must be whole pixels");
    d.resolution = {static_cast<int>(res[0]), static_cast<int>(res[1])};
    d.fx_px = r.number("fx_px", 1e-3, kBig, "(0, 1e6] px");
    d.fy_px = r.number("fy_px", 1e-3, kBig, "(0, 1e6] px");
    d.cx_px = r.number("cx_px", -kBig, kBig, "[-1e6, 1e6] px");
    d.cy_px = r.number("cy_px", -kBig, kBig, "[-1e6, 1e6] px");
    const std::vector<double> k = r.numbers("distortion", 5, -kBig, kBig, "[-1e6, 1e6]");
    std::copy(k.begin(), k.end(), d.distortion.begin());
    if (!camera) check_projector_distortion(r, d);
    d.rotation = read_rotation(r);
    const std::vector<double> p = r.numbers("position_m", 3, -1e3, 1e3, "[-1000, 1000] m");
    d.position_m = Eigen::Vector3d(p[0], p[1], p[2]);
    if (r.json().contains("falloff")) {
        if (camera) r.fail("falloff", " is a projector's (the camera has none)");
        const std::vector<double> c = r.numbers("falloff", 6, -10.0, 10.0, "[-10, 10]");
        std::copy(c.begin(), c.end(), d.falloff.c.begin());
        if (const auto bad = falloff_out_of_range(d)) {  // the relative light must stay a lens's
            r.fail("falloff", fmt::format(" gives {:.3g} at image position ({}, {}), outside [0.05, 5]", bad->z(),
                                          bad->x(), bad->y()));
        }
    }
    return d;
}

Json device_json(const DeviceModel& d) {
    Json rotation = Json::array();
    for (int i = 0; i < 3; ++i) rotation.push_back({d.rotation(i, 0), d.rotation(i, 1), d.rotation(i, 2)});
    Json out = {{"id", d.id},
                {"resolution", {d.resolution.width, d.resolution.height}},
                {"fx_px", d.fx_px},
                {"fy_px", d.fy_px},
                {"cx_px", d.cx_px},
                {"cy_px", d.cy_px},
                {"distortion", d.distortion},
                {"rotation", rotation},
                {"position_m", {d.position_m.x(), d.position_m.y(), d.position_m.z()}}};
    if (!d.falloff.flat()) out["falloff"] = d.falloff.c;  // absent = flat (files written before it read the same)
    return out;
}

}  // namespace

std::filesystem::path models_path_for(const std::filesystem::path& mpcdi) {
    std::filesystem::path p = mpcdi;
    p.replace_extension(".models.json");
    return p;
}

Json models_json(const CalibrationModels& m, const std::string& name) {
    Json projectors = Json::array();
    for (const DeviceModel& p : m.projectors) projectors.push_back(device_json(p));
    Json out = {{"format", kFormat},
                {"version", kVersion},
                {"screen",
                 {{"radius_m", m.screen.radius_m},
                  {"arc_deg", m.screen.arc_deg},
                  {"bottom_m", m.screen.bottom_m},
                  {"top_m", m.screen.top_m},
                  {"bow_m", m.screen.bow_m},
                  {"gain", m.screen.gain},
                  {"half_gain_angle_deg", m.screen.half_gain_angle_deg},
                  {"interreflection", m.screen.interreflection},
                  {"viewer_m", {m.screen.viewer_m.x(), m.screen.viewer_m.y(), m.screen.viewer_m.z()}}}},
                {"camera", device_json(m.camera)},
                {"projectors", projectors}};
    // nlohmann would write a non-finite number as null: validate so that what is written reads back.
    (void)models_from_json(out, name);
    return out;
}

CalibrationModels models_from_json(const Json& json, const std::string& name) {
    const Reader root(name, json, "");
    const Json& format = root.at("format");
    if (format != kFormat) root.fail("format", fmt::format(" = {} is not \"{}\"", format.dump(), kFormat));
    const Json& version = root.at("version");
    if (version != kVersion)
        root.fail("version", fmt::format(" = {} is not {} (the one this reader knows)", version.dump(), kVersion));
    CalibrationModels m;
    m.screen = read_screen(root.child("screen"));
    m.camera = read_device(root.child("camera"), true);
    const Json& projectors = root.at("projectors");
    if (!projectors.is_array() || projectors.empty() || projectors.size() > kMaxProjectors) {
        root.fail("projectors", fmt::format(" must be an array of 1 to {} projectors", kMaxProjectors));
    }
    for (std::size_t k = 0; k < projectors.size(); ++k) {
        m.projectors.push_back(read_device(Reader(name, projectors[k], fmt::format("projectors[{}]", k)), false));
    }
    return m;
}

void write_models(const std::filesystem::path& file, const CalibrationModels& models) {
    const std::string text = models_json(models, file.string()).dump(2) + "\n";
    write_file_atomically(file, std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

CalibrationModels read_models(const std::filesystem::path& file) {
    std::vector<std::uint8_t> bytes;
    try {
        bytes = read_file_bytes(file, std::uint64_t{16} << 20);
    } catch (const std::exception& e) {
        throw ModelStoreError(e.what());
    }
    const Json json = Json::parse(bytes.begin(), bytes.end(), nullptr, false);
    if (json.is_discarded()) throw ModelStoreError(fmt::format("{}: not valid JSON", file.string()));
    return models_from_json(json, file.string());
}

void check_models_match(const CalibrationModels& models, const ScreenCalibration& calibration,
                        const std::string& name) {
    if (models.projectors.size() != calibration.projectors.size()) {
        throw ModelStoreError(fmt::format("{}: projectors has {} entries, the calibration has {} projectors", name,
                                          models.projectors.size(), calibration.projectors.size()));
    }
    for (std::size_t k = 0; k < models.projectors.size(); ++k) {
        const DeviceModel& m = models.projectors[k];
        const ProjectorCalibration& c = calibration.projectors[k];
        if (m.id != c.id) {
            throw ModelStoreError(fmt::format(
                "{}: projectors[{}].id = \"{}\" but the calibration's projector {} is \"{}\"", name, k, m.id, k, c.id));
        }
        if (m.resolution.width != c.output.width || m.resolution.height != c.output.height) {
            throw ModelStoreError(
                fmt::format("{}: projectors[{}].resolution = {}x{} but the calibration's \"{}\" is {}x{}", name, k,
                            m.resolution.width, m.resolution.height, c.id, c.output.width, c.output.height));
        }
    }
}

}  // namespace mogao::autocal
