// SPDX-License-Identifier: Apache-2.0
// Rig files: TOML -> VirtualRig with every field checked (rig_file.h).
#include "appliance/rig/rig_file.h"

#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <string>

#include <toml.hpp>

#include "common/toml_nesting.h"

namespace mogao::rig {
namespace {

// One TOML table with its path in the file ("camera", "projectors[1]") for messages; every key
// read is remembered so that unknown keys (typos) are refused.
class Table {
public:
    Table(const toml::value& v, std::string where, const std::string& file) : file_(file), where_(std::move(where)) {
        if (!v.is_table()) fail("", "must be a table");
        table_ = &v.as_table();
    }

    [[noreturn]] void fail(const std::string& key, const std::string& why) const {
        throw RigError("rig file '" + file_ + "': " + where_ + (key.empty() ? "" : "." + key) + ": " + why);
    }

    const toml::value* find(const std::string& key) {
        known_.insert(key);
        const auto it = table_->find(key);
        return it == table_->end() ? nullptr : &it->second;
    }

    double number(const std::string& key, double fallback) {
        const toml::value* v = find(key);
        if (v == nullptr) return fallback;
        if (v->is_floating()) return v->as_floating();
        if (v->is_integer()) return static_cast<double>(v->as_integer());
        fail(key, "must be a number");
    }

    int integer(const std::string& key, int fallback) {
        const toml::value* v = find(key);
        if (v == nullptr) return fallback;
        // Any int: a drawn camera seed reaches 2^30 (tools/docs/regenerate_unseen_rigs_doc.py).
        if (!v->is_integer() || v->as_integer() < std::numeric_limits<int>::min() ||
            v->as_integer() > std::numeric_limits<int>::max())
            fail(key, "must be an integer in [" + std::to_string(std::numeric_limits<int>::min()) + ", " +
                          std::to_string(std::numeric_limits<int>::max()) + "]");
        return static_cast<int>(v->as_integer());
    }

    bool boolean(const std::string& key, bool fallback) {
        const toml::value* v = find(key);
        if (v == nullptr) return fallback;
        if (!v->is_boolean()) fail(key, "must be true or false");
        return v->as_boolean();
    }

    std::string string(const std::string& key, const std::string& fallback) {
        const toml::value* v = find(key);
        if (v == nullptr) return fallback;
        if (!v->is_string()) fail(key, "must be a string");
        return v->as_string().str;
    }

    template <std::size_t N>
    std::array<double, N> numbers(const std::string& key, std::array<double, N> fallback) {
        const toml::value* v = find(key);
        if (v == nullptr) return fallback;
        if (!v->is_array() || v->as_array().size() != N)
            fail(key, "must be an array of " + std::to_string(N) + " numbers");
        std::array<double, N> out{};
        for (std::size_t i = 0; i < N; ++i) {
            const toml::value& e = v->as_array()[i];
            if (e.is_floating()) {
                out[i] = e.as_floating();
            } else if (e.is_integer()) {
                out[i] = static_cast<double>(e.as_integer());
            } else {
                fail(key, "must be an array of " + std::to_string(N) + " numbers");
            }
        }
        return out;
    }

    Eigen::Vector3d vector3(const std::string& key, const Eigen::Vector3d& fallback) {
        const auto a = numbers<3>(key, {fallback.x(), fallback.y(), fallback.z()});
        return {a[0], a[1], a[2]};
    }

    ImageSize size(const std::string& key, ImageSize fallback) {
        const auto a = numbers<2>(key, {double(fallback.width), double(fallback.height)});
        if (a[0] != std::floor(a[0]) || a[1] != std::floor(a[1]) || a[0] < 1 || a[1] < 1 || a[0] > 16384 ||
            a[1] > 16384) {
            fail(key, "must be [width, height], integers 1..16384");
        }
        return {static_cast<int>(a[0]), static_cast<int>(a[1])};
    }

    void finish() const {
        for (const auto& [key, value] : *table_) {
            if (!known_.count(key)) fail(key, "unknown key");
        }
    }

private:
    std::string file_;
    std::string where_;
    const toml::table* table_ = nullptr;
    std::set<std::string> known_;
};

RigPose read_pose(Table& t) {
    RigPose pose;
    pose.position_m = t.vector3("position_m", pose.position_m);
    pose.yaw_deg = t.number("yaw_deg", 0.0);
    pose.pitch_deg = t.number("pitch_deg", 0.0);
    pose.roll_deg = t.number("roll_deg", 0.0);
    return pose;
}

RigProjector read_projector(Table& t, int k) {
    RigProjector p;
    p.id = t.string("id", "proj" + std::to_string(k));
    p.resolution = t.size("resolution", p.resolution);
    // Data-sheet terms: throw ratio = throw distance / image width, lens shift as a fraction of the
    // image (x right, y down; +0.5 in y puts the optical axis on the image's bottom edge).
    const double throw_ratio = t.number("throw_ratio", 1.0);
    const auto shift = t.numbers<2>("lens_shift", {0.0, 0.0});
    p.intrinsics.fx_px = p.intrinsics.fy_px = throw_ratio * p.resolution.width;
    p.intrinsics.cx_px = p.resolution.width * (0.5 + shift[0]);
    p.intrinsics.cy_px = p.resolution.height * (0.5 + shift[1]);
    p.pose = read_pose(t);
    p.gamma = t.numbers<3>("gamma", p.gamma);
    p.black_level = t.number("black_level", p.black_level);
    p.brightness = t.numbers<3>("brightness", p.brightness);
    p.falloff = t.number("falloff", p.falloff);
    // Lens distortion (OpenCV's k1, k2, p1, p2, k3 about the lens-shifted principal point) and defocus.
    p.intrinsics.distortion = t.numbers<5>("distortion", p.intrinsics.distortion);
    p.blur_px = t.number("blur_px", p.blur_px);
    const auto centre = t.numbers<2>("distortion_centre_px", {0.0, 0.0});
    p.distortion_centre_px = {centre[0], centre[1]};
    p.procam = t.string("procam", "");  // resolved against the file's folder by load_rig
    t.finish();
    return p;
}

RigCamera read_camera(Table& t) {
    RigCamera c;
    c.resolution = t.size("resolution", c.resolution);
    const auto f = t.numbers<2>("focal_px", {1000.0, 1000.0});
    const auto pp = t.numbers<2>("principal_point_px", {c.resolution.width / 2.0, c.resolution.height / 2.0});
    c.intrinsics = {f[0], f[1], pp[0], pp[1], t.numbers<5>("distortion", {})};
    c.pose = read_pose(t);
    c.exposure = t.number("exposure", c.exposure);
    c.gain = t.number("gain", c.gain);
    c.auto_exposure = t.boolean("auto_exposure", c.auto_exposure);
    c.read_noise = t.number("read_noise", c.read_noise);
    c.shot_noise = t.number("shot_noise", c.shot_noise);
    c.blur_sigma_px = t.number("blur_sigma_px", c.blur_sigma_px);
    c.bits = t.integer("bits", c.bits);
    c.supersample = t.integer("supersample", c.supersample);
    c.vignetting = t.number("vignetting", c.vignetting);
    c.mjpeg_quality = t.integer("mjpeg_quality", c.mjpeg_quality);
    c.straddle = t.number("straddle", c.straddle);
    const int seed = t.integer("seed", 1);
    if (seed < 0) t.fail("seed", "must be >= 0");
    c.seed = static_cast<std::uint64_t>(seed);
    t.finish();
    return c;
}

VirtualRig read_root(const toml::value& root, const std::string& file) {
    Table top(root, "rig", file);
    VirtualRig rig;
    rig.name = top.string("name", "rig");
    rig.ambient = top.number("ambient", rig.ambient);
    rig.viewer_m = top.vector3("viewer_position_m", rig.viewer_m);
    if (const toml::value* s = top.find("screen")) {
        Table t(*s, "screen", file);
        rig.screen.radius_m = t.number("radius_m", rig.screen.radius_m);
        rig.screen.arc_deg = t.number("arc_deg", rig.screen.arc_deg);
        rig.screen.bottom_m = t.number("bottom_m", rig.screen.bottom_m);
        rig.screen.top_m = t.number("top_m", rig.screen.top_m);
        rig.screen.bulge_m = t.number("bulge_m", rig.screen.bulge_m);
        rig.screen.gain = t.number("gain", rig.screen.gain);
        rig.screen.half_gain_angle_deg = t.number("half_gain_angle_deg", rig.screen.half_gain_angle_deg);
        rig.screen.interreflection = t.number("interreflection", rig.screen.interreflection);
        t.finish();
    }
    // One camera as [camera], or several as [[cameras]] (the first is the calibration's).
    const toml::value* c = top.find("camera");
    const toml::value* cs = top.find("cameras");
    if (c != nullptr && cs != nullptr) top.fail("cameras", "give either [camera] or [[cameras]], not both");
    if (c == nullptr && cs == nullptr) top.fail("camera", "missing [camera] section (or [[cameras]])");
    if (c != nullptr) {
        Table cam(*c, "camera", file);
        rig.camera = read_camera(cam);
    } else {
        if (!cs->is_array() || cs->as_array().empty() || cs->as_array().size() > 8) {
            top.fail("cameras", "must be 1..8 [[cameras]] tables");
        }
        for (std::size_t i = 0; i < cs->as_array().size(); ++i) {
            Table cam(cs->as_array()[i], "cameras[" + std::to_string(i) + "]", file);
            (i == 0 ? rig.camera : rig.more_cameras.emplace_back()) = read_camera(cam);
        }
    }
    if (const toml::value* p = top.find("prior")) {
        Table t(*p, "prior", file);
        rig.prior.camera_position_error_m = t.vector3("camera_position_error_m", rig.prior.camera_position_error_m);
        rig.prior.camera_angle_error_deg = t.vector3("camera_angle_error_deg", rig.prior.camera_angle_error_deg);
        rig.prior.camera_focal_error = t.number("camera_focal_error", 0.0);
        const auto pp = t.numbers<2>("camera_principal_point_error_px", {0.0, 0.0});
        rig.prior.camera_principal_point_error_px = {pp[0], pp[1]};
        rig.prior.camera_distortion_error = t.numbers<5>("camera_distortion_error", {});
        rig.prior.projector_focal_error = t.number("projector_focal_error", 0.0);
        rig.prior.screen_radius_error_m = t.number("screen_radius_error_m", 0.0);
        rig.prior.screen_arc_error_deg = t.number("screen_arc_error_deg", 0.0);
        rig.prior.screen_bottom_error_m = t.number("screen_bottom_error_m", 0.0);
        rig.prior.screen_top_error_m = t.number("screen_top_error_m", 0.0);
        rig.prior.screen_gain_error = t.number("screen_gain_error", 0.0);
        rig.prior.screen_half_gain_angle_error_deg = t.number("screen_half_gain_angle_error_deg", 0.0);
        t.finish();
    }
    const toml::value* ps = top.find("projectors");
    if (ps == nullptr || !ps->is_array()) top.fail("projectors", "missing [[projectors]] (1..16 of them)");
    for (std::size_t k = 0; k < ps->as_array().size(); ++k) {
        Table t(ps->as_array()[k], "projectors[" + std::to_string(k) + "]", file);
        rig.projectors.push_back(read_projector(t, static_cast<int>(k)));
    }
    top.finish();
    return rig;
}

}  // namespace

VirtualRig parse_rig(const std::string& toml_text, const std::string& name) {
    toml::value root;
    // toml11 recurses once per level and has no limit: a deep file would crash the reader.
    if (const auto excess = toml_nesting_excess(toml_text)) {
        throw RigError("rig file '" + name + "' line " + std::to_string(excess->line) +
                       ": tables or arrays nested deeper than " + std::to_string(excess->max_depth) + " levels");
    }
    // toml11 reads out of bounds on a literal string that is not UTF-8 (common/toml_nesting.h).
    if (const auto bad = toml_invalid_utf8(toml_text)) {
        throw RigError("rig file '" + name + "' line " + std::to_string(bad->line) + ": byte " +
                       std::to_string(bad->column) + " of the line is not UTF-8 (TOML files are UTF-8)");
    }
    try {
        std::istringstream in(toml_text);
        root = toml::parse(in, name);
    } catch (const std::exception& e) {
        throw RigError("rig file '" + name + "': not valid TOML: " + e.what());
    }
    VirtualRig rig = read_root(root, name);
    try {
        validate_rig(rig);
    } catch (const std::invalid_argument& e) {
        throw RigError("rig file '" + name + "': " + e.what());
    }
    return rig;
}

VirtualRig load_rig(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw RigError("rig file '" + path.string() + "': cannot be opened");
    std::ostringstream text;
    text << in.rdbuf();
    VirtualRig rig = parse_rig(text.str(), path.string());
    for (RigProjector& p : rig.projectors) {
        if (!p.procam.empty() && p.procam.is_relative()) p.procam = path.parent_path() / p.procam;
    }
    return rig;
}

}  // namespace mogao::rig
