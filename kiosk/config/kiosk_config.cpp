// SPDX-License-Identifier: Apache-2.0
#include "kiosk/config/kiosk_config.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <toml.hpp>

#include "appliance/tracker/tag_family.h"
#include "appliance/warp/late_warp.h"
#include "common/quality_preset.h"
#include "common/request_limits.h"
#include "common/toml_nesting.h"
#include "renderfarm/link/endpoint.h"

namespace mogao {
namespace {

using Value = toml::value;
namespace fs = std::filesystem;

constexpr int kMaxSide = request_limits::kImageSide.max;

std::string type_name(const Value& v) {
    switch (v.type()) {
        case toml::value_t::boolean:
            return "a boolean";
        case toml::value_t::integer:
            return "an integer";
        case toml::value_t::floating:
            return "a float";
        case toml::value_t::string:
            return "a string";
        case toml::value_t::offset_datetime:
        case toml::value_t::local_datetime:
        case toml::value_t::local_date:
        case toml::value_t::local_time:
            return "a date/time";
        case toml::value_t::array:
            return "an array";
        case toml::value_t::table:
            return "a table";
        case toml::value_t::empty:
            break;
    }
    return "nothing";
}

// Where messages point: the file, and the line of the offending value when toml11 knows it.
struct Context {
    std::string file;
    fs::path dir;  // relative paths are resolved against it

    [[noreturn]] void fail(const Value* where, const std::string& message) const {
        if (where != nullptr) {
            const auto line = where->location().line();
            if (line > 0 && where->location().file_name() != "unknown file") {
                throw KioskConfigError(fmt::format("{}:{}: {}", file, line, message));
            }
        }
        throw KioskConfigError(fmt::format("{}: {}", file, message));
    }

    [[nodiscard]] fs::path resolve(const std::string& text) const {
        const fs::path p(text);
        return (p.is_relative() ? dir / p : p).lexically_normal();
    }
};

// One [section]: typed getters that check ranges, and a final check for unknown keys.
class Section {
public:
    Section(const Context& ctx, std::string name, const Value* table, std::vector<std::string> known)
        : ctx_(ctx), name_(std::move(name)), table_(table), known_(std::move(known)) {}

    [[nodiscard]] std::string field(std::string_view key) const { return fmt::format("[{}].{}", name_, key); }

    [[nodiscard]] const Value* find(std::string_view key) const {
        if (table_ == nullptr) return nullptr;
        const auto& t = table_->as_table();
        const auto it = t.find(std::string(key));
        return it == t.end() ? nullptr : &it->second;
    }

    [[noreturn]] void fail(const Value* where, std::string_view key, const std::string& what) const {
        ctx_.fail(where != nullptr ? where : table_, field(key) + what);
    }

    [[nodiscard]] const Value& require(std::string_view key, std::string_view what) const {
        const Value* v = find(key);
        if (v == nullptr) fail(nullptr, key, fmt::format(" is required ({})", what));
        return *v;
    }

    [[nodiscard]] std::string string(std::string_view key, std::string fallback) const {
        const Value* v = find(key);
        return v == nullptr ? fallback : as_string(*v, key);
    }

    [[nodiscard]] std::string as_string(const Value& v, std::string_view key) const {
        if (!v.is_string()) fail(&v, key, ": expected a string, got " + type_name(v));
        return v.as_string().str;
    }

    [[nodiscard]] bool boolean(std::string_view key, bool fallback) const {
        const Value* v = find(key);
        if (v == nullptr) return fallback;
        if (!v->is_boolean()) fail(v, key, ": expected true or false, got " + type_name(*v));
        return v->as_boolean();
    }

    [[nodiscard]] int integer(std::string_view key, int fallback, int lo, int hi) const {
        const Value* v = find(key);
        if (v == nullptr) return fallback;
        if (!v->is_integer()) fail(v, key, ": expected an integer, got " + type_name(*v));
        const std::int64_t n = v->as_integer();
        if (n < lo || n > hi) fail(v, key, fmt::format(" = {} is outside [{}, {}]", n, lo, hi));
        return static_cast<int>(n);
    }

    [[nodiscard]] int integer(std::string_view key, int fallback, IntRange range) const {
        return integer(key, fallback, range.min, range.max);
    }

    // A number (integer or float) that `ok` accepts; `range` describes the limit in messages.
    [[nodiscard]] double number(std::string_view key, double fallback, const std::function<bool(double)>& ok,
                                std::string_view range) const {
        const Value* v = find(key);
        if (v == nullptr) return fallback;
        return as_number(*v, key, ok, range);
    }

    [[nodiscard]] double as_number(const Value& v, std::string_view key, const std::function<bool(double)>& ok,
                                   std::string_view range) const {
        double x = 0;
        if (v.is_integer()) {
            x = static_cast<double>(v.as_integer());
        } else if (v.is_floating()) {
            x = v.as_floating();
        } else {
            fail(&v, key, ": expected a number, got " + type_name(v));
        }
        if (!std::isfinite(x) || !ok(x)) fail(&v, key, fmt::format(" = {} is outside {}", x, range));
        return x;
    }

    [[nodiscard]] ImageSize size(std::string_view key, ImageSize fallback, int lo) const {
        const Value* v = find(key);
        return v == nullptr ? fallback : as_size(*v, key, lo);
    }

    [[nodiscard]] ImageSize as_size(const Value& v, std::string_view key, int lo) const {
        const std::string text = as_string(v, key);
        ImageSize s;
        if (!parse_size(text, s)) fail(&v, key, fmt::format(": '{}' is not WIDTHxHEIGHT (e.g. \"1920x1080\")", text));
        if (s.width < lo || s.width > kMaxSide || s.height < lo || s.height > kMaxSide) {
            fail(&v, key, fmt::format(" = '{}' is outside [{}, {}] pixels per side", text, lo, kMaxSide));
        }
        return s;
    }

    // A path to an existing regular file.
    [[nodiscard]] fs::path existing_file(const Value& v, std::string_view key) const {
        const std::string text = as_string(v, key);
        if (text.empty()) fail(&v, key, ": empty path");
        const fs::path p = ctx_.resolve(text);
        std::error_code ec;
        if (!fs::exists(p, ec)) fail(&v, key, fmt::format(": '{}' does not exist", p.string()));
        if (!fs::is_regular_file(p, ec)) fail(&v, key, fmt::format(": '{}' is not a regular file", p.string()));
        return p;
    }

    // Keys only meaningful in one mode ("only with backend = \"headless\"").
    void forbid(std::string_view key, std::string_view reason) const {
        if (const Value* v = find(key)) fail(v, key, fmt::format(": only {}", reason));
    }

    // Unknown keys are errors: a typo must not fall back to a default silently.
    void finish() const {
        if (table_ == nullptr) return;
        std::set<std::string> unknown;
        for (const auto& [key, value] : table_->as_table()) {
            if (std::find(known_.begin(), known_.end(), key) == known_.end()) unknown.insert(key);
        }
        if (unknown.empty()) return;
        const std::string& key = *unknown.begin();
        fail(&table_->as_table().at(key), key, fmt::format(": unknown field (known: {})", fmt::join(known_, ", ")));
    }

    [[nodiscard]] const Context& context() const { return ctx_; }

private:
    const Context& ctx_;
    std::string name_;
    const Value* table_;
    std::vector<std::string> known_;
};

Section section(const Context& ctx, const Value& root, const std::string& name, std::vector<std::string> known) {
    const auto& t = root.as_table();
    const auto it = t.find(name);
    if (it == t.end()) return Section(ctx, name, nullptr, std::move(known));
    if (!it->second.is_table())
        ctx.fail(&it->second, fmt::format("[{}]: expected a table, got {}", name, type_name(it->second)));
    return Section(ctx, name, &it->second, std::move(known));
}

void read_farm(const Section& s, FarmConfig& farm) {
    const Value& endpoint = s.require("endpoint", "the farm as \"[address]:port\"");
    farm.endpoint = s.as_string(endpoint, "endpoint");
    std::string why;
    const auto parsed = parse_endpoint(farm.endpoint, &why);
    if (!parsed) s.fail(&endpoint, "endpoint", ": " + why);
    if (parsed->port == 0)
        s.fail(&endpoint, "endpoint", fmt::format(": '{}' has port 0 (the farm's port is 1..65535)", farm.endpoint));
    if (parsed->is_wildcard())
        s.fail(&endpoint, "endpoint", fmt::format(": '{}' is the wildcard address, not a farm", farm.endpoint));
    farm.server_name = s.string("server_name", "");
    farm.ca = s.existing_file(s.require("ca", "PEM file of the farm CA"), "ca");
    farm.cert = s.existing_file(s.require("cert", "PEM file of this appliance's certificate"), "cert");
    farm.key = s.existing_file(s.require("key", "PEM file of this appliance's private key"), "key");
}

void read_outputs(const Section& display, const Section& s, OutputsConfig& out) {
    out.rate_hz = display.number(
        "rate_hz", out.rate_hz, [](double x) { return x >= 0.5 && x <= 240; }, "[0.5, 240] Hz");
    out.flip_timeout_s = display.number(
        "flip_timeout_s", out.flip_timeout_s, [](double x) { return x == 0.0 || (x >= 1.0 && x <= 600.0); },
        "0 (off) or [1, 600] s");
    const Value* backend = s.find("backend");
    if (backend != nullptr) {
        const std::string kind = s.as_string(*backend, "backend");
        if (kind == "headless") {
            out.backend = OutputKind::headless;
        } else if (kind == "kms") {
            out.backend = OutputKind::kms;
        } else {
            s.fail(backend, "backend", fmt::format(": '{}' is not one of headless, kms", kind));
        }
    }
    if (out.backend == OutputKind::kms) {
        for (const char* key : {"sizes", "png_dir", "png_every", "composite"})
            s.forbid(key, "with backend = \"headless\"");
        const std::string device = s.string("device", "");
        if (!device.empty()) out.device = s.context().resolve(device);
        return;
    }
    s.forbid("device", "with backend = \"kms\"");
    if (const Value* sizes = s.find("sizes")) {
        if (!sizes->is_array())
            s.fail(sizes, "sizes", ": expected an array of \"WIDTHxHEIGHT\" strings, got " + type_name(*sizes));
        const auto& list = sizes->as_array();
        if (list.empty() || list.size() > 64)
            s.fail(sizes, "sizes", fmt::format(": {} outputs is outside [1, 64]", list.size()));
        for (std::size_t i = 0; i < list.size(); ++i) {
            out.sizes.push_back(s.as_size(list[i], fmt::format("sizes[{}]", i), 1));
        }
    }
    const std::string png_dir = s.string("png_dir", "");
    if (!png_dir.empty()) out.png_dir = s.context().resolve(png_dir);
    out.png_every = s.integer("png_every", out.png_every, 1, 1'000'000);
    out.composite = s.boolean("composite", out.composite);
}

void read_calibration(const Section& s, CalibrationConfig& c) {
    const Value* source = s.find("source");
    const std::string text = source == nullptr ? "ideal" : s.as_string(*source, "source");
    if (text != "ideal") {
        c.mpcdi = s.existing_file(*source, "source");
        c.watch = s.boolean("watch", c.watch);
        for (const char* key : {"projectors", "overlap", "output", "gamma"}) s.forbid(key, "with source = \"ideal\"");
        return;
    }
    s.forbid("watch", "with an MPCDI source (the ideal layout never changes)");
    c.projectors = s.integer("projectors", c.projectors, 1, 64);
    c.overlap = s.number(
        "overlap", c.overlap, [](double x) { return x >= 0 && x < 0.5; }, "[0, 0.5)");
    c.output = s.size("output", c.output, 1);
    c.gamma = s.number(
        "gamma", c.gamma, [](double x) { return x > 0 && x <= 10; }, "(0, 10]");
}

void read_quality(const Section& s, QualityConfig& q) {
    // A preset (common/quality_preset.h, the farm's table) first; the explicit keys below override it.
    if (const Value* preset = s.find("preset"); preset != nullptr) {
        const std::string name = s.as_string(*preset, "preset");
        const QualityPreset* p = quality_preset(name);
        if (p == nullptr)
            s.fail(preset, "preset", fmt::format(": '{}' is not one of {}", name, quality_preset_names()));
        q.preset = name;
        q.spp = p->request.spp;
        q.jpeg_quality = p->request.jpeg_quality;
        q.max_bounces = p->request.max_bounces;
        q.ao_samples = p->request.ao_samples;
        q.area_light_samples = p->request.area_light_samples;
    }
    q.content = s.size("content", q.content, request_limits::kLinkImageSide.min);
    q.spp = s.integer("spp", q.spp, request_limits::kSpp);
    q.jpeg_quality = s.integer("jpeg_quality", q.jpeg_quality, request_limits::kJpegQuality);
    q.max_bounces = s.integer("bounces", q.max_bounces, request_limits::kMaxBounces);
    q.ao_samples = s.integer("ao_samples", q.ao_samples, request_limits::kAoSamples);
    q.area_light_samples = s.integer("area_light_samples", q.area_light_samples, request_limits::kAreaLightSamples);
}

void read_screen(const Section& s, CylinderScreen& screen, double& guard_deg) {
    screen.radius_m = s.number(
        "radius_m", screen.radius_m, [](double x) { return x > 0 && x <= 1000; }, "(0, 1000] m");
    screen.arc_deg = s.number(
        "arc_deg", screen.arc_deg, [](double x) { return x > 0 && x <= 360; }, "(0, 360] degrees");
    const auto height = [](double x) { return std::abs(x) <= 1000; };
    screen.bottom_m = s.number("bottom_m", screen.bottom_m, height, "[-1000, 1000] m");
    screen.top_m = s.number("top_m", screen.top_m, height, "[-1000, 1000] m");
    if (!(screen.top_m > screen.bottom_m)) {
        s.fail(s.find("top_m") != nullptr ? s.find("top_m") : s.find("bottom_m"), "top_m",
               fmt::format(" = {} must be above [screen].bottom_m = {}", screen.top_m, screen.bottom_m));
    }
    // The late warp's guard band (appliance/warp/late_warp.h): the widened arc must stay a cylinder.
    const double max_guard = (360.0 - screen.arc_deg) / 2.0;
    guard_deg = s.number(
        "guard_deg", guard_deg, [max_guard](double x) { return x >= 0 && x <= max_guard; },
        fmt::format("[0, {}] degrees: arc_deg + 2 * guard_deg <= 360", max_guard));
}

// The guarded frame the farm is asked for must fit the link's image limit.
void check_guarded_width(const Section& s, const KioskConfig& config) {
    const auto guarded = guard_band(config.screen, config.quality.content, config.guard_deg);
    if (!guarded) s.fail(s.find("guard_deg"), "guard_deg", ": " + guarded.error().message);
    if (guarded->size.width > request_limits::kLinkImageSide.max) {
        s.fail(s.find("guard_deg"), "guard_deg",
               fmt::format(" = {} widens [quality].content to {} columns, beyond the link's {}", config.guard_deg,
                           guarded->size.width, request_limits::kLinkImageSide.max));
    }
}

// A [section.sub] table inside `parent` (e.g. [navigation.detector]); absent: an empty section.
Section subsection(const Section& parent, std::string_view key, const std::string& name,
                   std::vector<std::string> known) {
    const Value* v = parent.find(key);
    if (v != nullptr && !v->is_table())
        parent.fail(v, key, ": expected a table ([" + name + "]), got " + type_name(*v));
    return Section(parent.context(), name, v, std::move(known));
}

const std::vector<std::string> kCameraControlKeys{"camera_exposure_us", "camera_gain", "camera_white_balance_k",
                                                  "camera_colour"};
// clang-format off
const std::vector<std::string> kTrackingKeys{
    "camera", "camera_size", "camera_fps", "intrinsics", "tag_size_m", "tag_id", "replay_end", "detector", "roi",
    "control", "camera_exposure_us", "camera_gain", "camera_white_balance_k", "camera_colour"};
// clang-format on

// [navigation]'s keys: the scripted visitor's and the start pose, then the tracking keys.
std::vector<std::string> navigation_keys() {
    std::vector<std::string> keys{"source", "path", "path_frames", "start", "start_yaw_deg", "eye_height_m"};
    keys.insert(keys.end(), kTrackingKeys.begin(), kTrackingKeys.end());
    return keys;
}

// One camera control key: "auto", "lock", "keep" or a number within `range` (the device's own range
// is checked when the camera opens; the setting carries the key's name for that message). Written:
// required (a camera without the control is an error); absent: `fallback`, not required.
ControlSetting read_control_setting(const Section& s, std::string_view key, ControlSetting fallback,
                                    const std::function<bool(double)>& ok, std::string_view range) {
    ControlSetting setting = std::move(fallback);
    setting.name = fmt::format("{}: {}", s.context().file, s.field(key));
    const Value* v = s.find(key);
    if (v == nullptr) return setting;
    setting.required = true;
    if (v->is_string()) {
        const std::string text = v->as_string().str;
        if (text == "auto") {
            setting.mode = ControlSetting::Mode::automatic;
        } else if (text == "lock") {
            setting.mode = ControlSetting::Mode::lock;
        } else if (text == "keep") {
            setting.mode = ControlSetting::Mode::keep;
        } else {
            s.fail(v, key, fmt::format(": '{}' is not one of auto, lock, keep or a number in {}", text, range));
        }
        return setting;
    }
    setting.mode = ControlSetting::Mode::manual;
    setting.value = s.as_number(*v, key, ok, range);
    return setting;
}

// The camera control keys of a live camera (CameraControls, drivers/camera/camera_controls.h).
void read_camera_controls(const Section& s, CameraSourceSpec& source) {
    // A short exposure by default (kDefaultExposureUs): a hand moving at 1 m/s blurs by 2 mm.
    const ControlSetting short_exposure{ControlSetting::Mode::manual, kDefaultExposureUs, false, ""};
    source.controls.exposure = read_control_setting(
        s, "camera_exposure_us", short_exposure, [](double x) { return x > 0 && x <= 1e6; }, "(0, 1e6] us");
    source.controls.gain = read_control_setting(
        s, "camera_gain", {}, [](double x) { return x >= 0 && x <= 1e6; }, "[0, 1e6]");
    source.controls.white_balance = read_control_setting(
        s, "camera_white_balance_k", {}, [](double x) { return x >= 1000 && x <= 20000; }, "[1000, 20000] K");
    source.colour = s.boolean("camera_colour", false);
}

void read_detector(const Section& s, DetectorSettings& d) {
    d.family = s.string("family", d.family);
    const auto within = [](double lo, double hi) { return [lo, hi](double x) { return x >= lo && x <= hi; }; };
    d.decimation = static_cast<float>(s.number("decimation", d.decimation, within(1, 8), "[1, 8]"));
    d.blur_sigma = static_cast<float>(s.number("blur_sigma", d.blur_sigma, within(-5, 5), "[-5, 5] px"));
    d.refine_edges = s.boolean("refine_edges", d.refine_edges);
    d.min_white_black_diff = s.integer("min_white_black_diff", d.min_white_black_diff, 0, 255);
    d.decode_sharpening = s.number("decode_sharpening", d.decode_sharpening, within(0, 1), "[0, 1]");
    d.max_hamming = s.integer("max_hamming", d.max_hamming, 0, 2);
    d.threads = s.integer("threads", d.threads, 1, 64);
    const auto& families = TagFamily::known_names();
    if (std::find(families.begin(), families.end(), d.family) == families.end()) {
        s.fail(s.find("family"), "family", fmt::format(": '{}' is not one of {}", d.family, fmt::join(families, ", ")));
    }
    try {
        validate(d);
    } catch (const std::invalid_argument& e) {
        s.context().fail(nullptr, fmt::format("[navigation.detector]: {}", e.what()));
    }
}

// [navigation.roi]: the keys an operator may need (a busy or an idle hall); the window's geometry
// stays as tag_tracker.h measured it.
void read_roi(const Section& s, RoiSettings& r) {
    r.enabled = s.boolean("enabled", r.enabled);
    r.full_search_every = s.integer("full_search_every", r.full_search_every, 0, 100000);
    r.window_tag_px = s.number(
        "window_tag_px", r.window_tag_px, [](double x) { return x == 0 || (x >= 4 && x <= 1000); },
        "0 or [4, 1000] px");
    const auto seconds = [](double x) { return x >= 0 && x <= 3600; };
    r.idle_after_s = s.number("idle_after_s", r.idle_after_s, seconds, "[0, 3600] s");
    r.idle_search_period_s = s.number("idle_search_period_s", r.idle_search_period_s, seconds, "[0, 3600] s");
}

void read_control(const Section& s, NavigationParams& p) {
    const auto any = [](double x) { return std::abs(x) <= 1e6; };
    const auto non_negative = [](double x) { return x >= 0 && x <= 1e6; };
    const auto positive = [](double x) { return x > 0 && x <= 1e6; };
    const auto exponent = [](double x) { return x >= 1 && x <= 4; };
    struct Field {
        const char* key;
        double* value;
        std::function<bool(double)> ok;
        const char* range;
    };
    const Field fields[] = {
        {"rest_yaw_deg", &p.rest.yaw_deg, any, "[-1e6, 1e6] degrees"},
        {"rest_pitch_deg", &p.rest.pitch_deg, any, "[-1e6, 1e6] degrees"},
        {"rest_distance_m", &p.rest.distance_m, positive, "(0, 1e6] m"},
        {"rest_lateral_m", &p.rest.lateral_m, any, "[-1e6, 1e6] m"},
        {"turn_dead_zone_deg", &p.turn.dead_zone, non_negative, "[0, 1e6] degrees"},
        {"turn_full_scale_deg", &p.turn.full_scale, positive, "(0, 1e6] degrees, above the dead zone"},
        {"turn_max_deg_s", &p.turn.max_rate, non_negative, "[0, 1e6] deg/s"},
        {"turn_exponent", &p.turn.exponent, exponent, "[1, 4]"},
        {"forward_dead_zone_m", &p.forward.dead_zone, non_negative, "[0, 1e6] m"},
        {"forward_full_scale_m", &p.forward.full_scale, positive, "(0, 1e6] m, above the dead zone"},
        {"forward_max_m_s", &p.forward.max_rate, non_negative, "[0, 1e6] m/s"},
        {"forward_exponent", &p.forward.exponent, exponent, "[1, 4]"},
        {"strafe_dead_zone_m", &p.strafe.dead_zone, non_negative, "[0, 1e6] m"},
        {"strafe_full_scale_m", &p.strafe.full_scale, positive, "(0, 1e6] m, above the dead zone"},
        {"strafe_max_m_s", &p.strafe.max_rate, non_negative, "[0, 1e6] m/s (0 = off)"},
        {"strafe_exponent", &p.strafe.exponent, exponent, "[1, 4]"},
        {"max_angular_accel_deg_s2", &p.max_angular_accel_deg_s2, positive, "(0, 1e6] deg/s^2"},
        {"max_linear_accel_m_s2", &p.max_linear_accel_m_s2, positive, "(0, 1e6] m/s^2"},
        {"hold_s", &p.hold_s, [](double x) { return x >= 0 && x <= 60; }, "[0, 60] s"},
        {"forget_s", &p.forget_s, [](double x) { return x >= 0 && x <= 3600; }, "[0, 3600] s"},
        {"max_dt_s", &p.max_dt_s, [](double x) { return x > 0 && x <= 10; }, "(0, 10] s"},
    };
    for (const Field& f : fields) *f.value = s.number(f.key, *f.value, f.ok, f.range);
    p.pitch.enabled = s.boolean("pitch", p.pitch.enabled);
    try {
        validate(p);  // the relations: full scale above dead zone, hold_s <= forget_s
    } catch (const std::invalid_argument& e) {
        s.context().fail(nullptr, fmt::format("[{}]: {}", "navigation.control", e.what()));
    }
}

void read_tracking(const Section& s, TrackingConfig& t, double eye_height_m) {
    const Value& camera = s.require(
        "camera", "with source = \"tracking\": \"replay:<folder>\", \"v4l2:/dev/videoN\" or \"libcamera:[<id>]\"");
    t.camera = s.as_string(camera, "camera");
    std::string why;
    if (!parse_camera_source(t.camera, t.source, &why)) s.fail(&camera, "camera", ": " + why);
    const bool replay = t.source.kind == CameraSourceSpec::Kind::replay;
    if (replay) {
        t.source.folder = s.context().resolve(t.source.folder.string());
        std::error_code ec;
        if (!fs::is_directory(t.source.folder, ec)) {
            s.fail(&camera, "camera", fmt::format(": replay folder '{}' does not exist", t.source.folder.string()));
        }
        s.forbid("camera_size",
                 "with a live camera, \"v4l2:\" or \"libcamera:\" (a replay has the size of its images)");
        t.source.replay_fps = s.number(
            "camera_fps", t.source.replay_fps, [](double x) { return x > 0 && x <= 1000; },
            "(0, 1000] Hz (replay rate without timestamps.txt)");
        if (const Value* end = s.find("replay_end")) {
            const std::string text = s.as_string(*end, "replay_end");
            if (text == "stop") {
                t.replay_end = ReplayEnd::stop;
            } else if (text == "loop") {
                t.replay_end = ReplayEnd::loop;
            } else if (text == "idle") {
                t.replay_end = ReplayEnd::idle;
            } else {
                s.fail(end, "replay_end", fmt::format(": '{}' is not one of stop, loop, idle", text));
            }
        }
        t.source.loop = t.replay_end == ReplayEnd::loop;
        for (const auto& key : kCameraControlKeys) {
            s.forbid(key, "with a live camera, \"v4l2:\" or \"libcamera:\" (a replay has no camera controls)");
        }
    } else {
        read_camera_controls(s, t.source);
        const bool v4l2 = t.source.kind == CameraSourceSpec::Kind::v4l2;
        if (v4l2 && !fs::path(t.source.device).is_absolute()) {
            s.fail(&camera, "camera",
                   fmt::format(": '{}' is not an absolute device path (\"v4l2:/dev/videoN\")", t.source.device));
        }
        s.forbid("replay_end", "with a \"replay:\" camera");
        if (!v4l2)
            s.forbid("camera_fps", "with a \"replay:\" or \"v4l2:\" camera (libcamera runs its pipeline's own rate)");
        t.source.fps = s.integer("camera_fps", 0, 0, 240);
    }
    const Value* intrinsics = s.find("intrinsics");
    if (intrinsics != nullptr) {
        t.intrinsics_file = s.existing_file(*intrinsics, "intrinsics");
    } else if (replay && fs::exists(t.source.folder / "camera.json")) {
        t.intrinsics_file = t.source.folder / "camera.json";
    } else {
        s.fail(nullptr, "intrinsics",
               replay ? fmt::format(" is required (the camera calibration, JSON or OpenCV YAML; "
                                    "'{}' has no camera.json)",
                                    t.source.folder.string())
                      : std::string(" is required with a live camera (\"v4l2:\" or \"libcamera:\"; "
                                    "the camera calibration, JSON or OpenCV YAML)"));
    }
    try {
        t.intrinsics = read_intrinsics(t.intrinsics_file);
    } catch (const std::exception& e) {
        s.fail(intrinsics, "intrinsics", fmt::format(": {}", e.what()));
    }
    if (!replay) {
        const ImageSize calibrated{t.intrinsics.width, t.intrinsics.height};
        const ImageSize size = s.size("camera_size", calibrated, 1);
        if (size.width > 8192 || size.height > 8192) {
            s.fail(s.find("camera_size"), "camera_size", " is outside [1, 8192] pixels per side");
        }
        if (size.width != calibrated.width || size.height != calibrated.height) {
            t.intrinsics = rescale(t.intrinsics, size.width, size.height);  // a binned mode of the calibrated sensor
        }
        t.source.width = size.width;
        t.source.height = size.height;
    }
    t.tag_size_m = s.number(
        "tag_size_m", t.tag_size_m, [](double x) { return x > 0 && x <= 10; }, "(0, 10] m");
    t.tag_id = s.integer("tag_id", t.tag_id, 0, 1'000'000);
    const Section detector = subsection(s, "detector", "navigation.detector",
                                        {"family", "decimation", "blur_sigma", "refine_edges", "min_white_black_diff",
                                         "decode_sharpening", "max_hamming", "threads"});
    read_detector(detector, t.detector);
    detector.finish();
    const Section roi =
        subsection(s, "roi", "navigation.roi",
                   {"enabled", "full_search_every", "window_tag_px", "idle_after_s", "idle_search_period_s"});
    read_roi(roi, t.roi);
    roi.finish();
    const Section control = subsection(s, "control", "navigation.control",
                                       {"rest_yaw_deg",
                                        "rest_pitch_deg",
                                        "rest_distance_m",
                                        "rest_lateral_m",
                                        "turn_dead_zone_deg",
                                        "turn_full_scale_deg",
                                        "turn_max_deg_s",
                                        "turn_exponent",
                                        "forward_dead_zone_m",
                                        "forward_full_scale_m",
                                        "forward_max_m_s",
                                        "forward_exponent",
                                        "strafe_dead_zone_m",
                                        "strafe_full_scale_m",
                                        "strafe_max_m_s",
                                        "strafe_exponent",
                                        "pitch",
                                        "max_angular_accel_deg_s2",
                                        "max_linear_accel_m_s2",
                                        "hold_s",
                                        "forget_s",
                                        "max_dt_s"});
    t.params.eye_height_m = eye_height_m;
    read_control(control, t.params);
    control.finish();
}

void read_navigation(const Section& s, NavigationConfig& n) {
    if (const Value* source = s.find("source")) {
        const std::string text = s.as_string(*source, "source");
        if (text == "path") {
            n.source = NavigationSource::path;
        } else if (text == "tracking") {
            n.source = NavigationSource::tracking;
        } else {
            s.fail(source, "source", fmt::format(": '{}' is not one of path, tracking", text));
        }
    }
    if (n.source == NavigationSource::path) {
        for (const auto& key : kTrackingKeys) s.forbid(key, "with source = \"tracking\"");
    } else {
        for (const char* key : {"path", "path_frames"}) s.forbid(key, "with source = \"path\"");
    }
    if (const Value* path = s.find("path")) {
        const std::string text = s.as_string(*path, "path");
        if (text == "walk" || text == "orbit") {
            n.path = text;
        } else if (text.empty()) {
            s.fail(path, "path", ": empty (expected walk, orbit or a JSON path file)");
        } else {
            n.path = s.existing_file(*path, "path").string();
        }
    }
    n.path_frames = s.integer("path_frames", n.path_frames, 2, 1'000'000);
    if (const Value* start = s.find("start")) {
        if (!start->is_array() || start->as_array().size() != 3) {
            s.fail(start, "start", ": expected [x, y, z] (floor point of the viewer's start, metres)");
        }
        for (std::size_t i = 0; i < 3; ++i) {
            n.start[static_cast<Eigen::Index>(i)] = s.as_number(
                start->as_array()[i], fmt::format("start[{}]", i), [](double x) { return std::abs(x) <= 1e9; },
                "[-1e9, 1e9] m");
        }
    }
    n.start_yaw_deg = s.number(
        "start_yaw_deg", n.start_yaw_deg, [](double x) { return std::abs(x) <= 3600; }, "[-3600, 3600] degrees");
    n.eye_height_m = s.number(
        "eye_height_m", n.eye_height_m, [](double x) { return x > 0 && x <= 100; }, "(0, 100] m");
    if (n.source == NavigationSource::tracking) read_tracking(s, n.tracking, n.eye_height_m);
}

void read_stats(const Section& s, StatsConfig& st) {
    const std::string file = s.string("file", "");
    if (!file.empty()) st.file = s.context().resolve(file);
    st.log_period_s = s.number(
        "log_period_s", st.log_period_s, [](double x) { return x >= 0.1 && x <= 86400; }, "[0.1, 86400] s");
    const std::string status = s.string("status_file", "");
    if (!status.empty()) st.status_file = s.context().resolve(status);
    st.status_period_s = s.number(
        "status_period_s", st.status_period_s, [](double x) { return x >= 0.1 && x <= 3600; }, "[0.1, 3600] s");
    const std::string metrics = s.string("metrics_file", "");
    if (!metrics.empty()) st.metrics_file = s.context().resolve(metrics);
}

void read_status(const Section& s, StatusConfig& st) {
    if (const Value* on_wall = s.find("on_wall")) {
        const std::string text = s.as_string(*on_wall, "on_wall");
        if (text == "off") {
            st.on_wall = OnWall::off;
        } else if (text == "on_demand") {
            st.on_wall = OnWall::on_demand;
        } else if (text == "always") {
            st.on_wall = OnWall::always;
        } else {
            s.fail(on_wall, "on_wall", fmt::format(": '{}' is not one of off, on_demand, always", text));
        }
    }
    const std::string trigger = s.string("trigger_file", "");
    if (!trigger.empty()) {
        if (st.on_wall != OnWall::on_demand) s.forbid("trigger_file", "with on_wall = \"on_demand\"");
        st.trigger_file = s.context().resolve(trigger);
    }
    st.farm_lost_after_s = s.number(
        "farm_lost_after_s", st.farm_lost_after_s, [](double x) { return x >= 0 && x <= 86400; },
        "[0, 86400] s (0 = never)");
    st.certificate_warning_days = s.number(
        "certificate_warning_days", st.certificate_warning_days, [](double x) { return x >= 0 && x <= 3650; },
        "[0, 3650] days (0 = never)");
}

// A screen camera's exposure or gain: "lock" (default: hold what the automatic loop reached) or a
// manual value; never automatic, never left as the device has it (the monitor compares frames
// taken minutes apart: a camera re-metering each frame would change what it sees).
ControlSetting locked_control(const Section& s, std::string_view key, const std::function<bool(double)>& ok,
                              std::string_view range) {
    ControlSetting setting = read_control_setting(s, key, {ControlSetting::Mode::lock, 0.0, true, ""}, ok, range);
    setting.required = true;  // a screen camera without the control cannot be trusted to hold still
    if (setting.mode == ControlSetting::Mode::automatic || setting.mode == ControlSetting::Mode::keep) {
        s.fail(s.find(key), key, fmt::format(": the screen camera's {} must be \"lock\" or a value in {}", key, range));
    }
    return setting;
}

void read_selfcal_camera(const Section& s, SelfcalConfig& sc) {
    const Value& camera =
        s.require("camera", "with enabled = true: \"v4l2:/dev/videoN\", or \"rig:<rig.toml>\" (a simulation)");
    sc.camera = s.as_string(camera, "camera");
    const std::string_view text = sc.camera;
    if (text.starts_with("rig:")) {
        sc.kind = SelfcalConfig::CameraKind::rig;
        const std::string file(text.substr(4));
        if (file.empty()) s.fail(&camera, "camera", ": \"rig:\" needs the virtual rig's file (rig:<rig.toml>)");
        sc.rig = s.context().resolve(file);
        std::error_code ec;
        if (!fs::is_regular_file(sc.rig, ec)) {
            s.fail(&camera, "camera", fmt::format(": rig file '{}' does not exist", sc.rig.string()));
        }
        for (const char* key : {"camera_size", "camera_exposure_us", "camera_gain"}) {
            s.forbid(key, "with a \"v4l2:\" camera (the rig's camera is simulated)");
        }
        return;
    }
    std::string why;
    if (!text.starts_with("v4l2:") || !parse_camera_source(sc.camera, sc.source, &why)) {
        s.fail(&camera, "camera", fmt::format(": '{}' is not \"v4l2:/dev/videoN\" or \"rig:<rig.toml>\"", sc.camera));
    }
    sc.kind = SelfcalConfig::CameraKind::v4l2;
    if (!fs::path(sc.source.device).is_absolute()) {
        s.fail(&camera, "camera", fmt::format(": '{}' is not an absolute device path", sc.source.device));
    }
    const ImageSize size = s.size("camera_size", {0, 0}, 1);
    sc.source.width = size.width;  // 0: the models' camera resolution (kiosk_setup)
    sc.source.height = size.height;
    sc.source.controls.exposure = locked_control(
        s, "camera_exposure_us", [](double x) { return x > 0 && x <= 1e6; }, "(0, 1e6] us");
    sc.source.controls.gain = locked_control(
        s, "camera_gain", [](double x) { return x >= 0 && x <= 1e6; }, "[0, 1e6]");
}

void read_selfcal(const Section& s, const CalibrationConfig& calibration, SelfcalConfig& sc) {
    sc.enabled = s.boolean("enabled", false);
    if (!sc.enabled) return;  // the other keys may stay written while it is off (unknown ones still fail)
    if (calibration.mpcdi.empty()) {
        s.fail(s.find("enabled"), "enabled",
               " = true needs [calibration].source to be an MPCDI file (the fitted calibration that "
               "self-recalibration corrects and writes back), not \"ideal\"");
    }
    read_selfcal_camera(s, sc);
    if (const Value* models = s.find("models")) {
        sc.models = s.existing_file(*models, "models");
    } else {
        sc.models = calibration.mpcdi;
        sc.models.replace_extension(".models.json");  // autocal::models_path_for
        std::error_code ec;
        if (!fs::is_regular_file(sc.models, ec)) {
            s.fail(nullptr, "models",
                   fmt::format(" is required: '{}' (beside the MPCDI, written by mogao-autocal calibrate) does not "
                               "exist",
                               sc.models.string()));
        }
    }
    sc.rate_hz = s.number(
        "rate_hz", sc.rate_hz, [](double x) { return x > 0 && x <= 2; }, "(0, 2] Hz");
    sc.hold_s = s.number(
        "hold_s", sc.hold_s, [](double x) { return x >= 0 && x <= 600; }, "[0, 600] s");
    sc.transition_s = s.number(
        "transition_s", sc.transition_s, [](double x) { return x >= 0 && x <= 600; }, "[0, 600] s");
    sc.drift_threshold_px = s.number(
        "drift_threshold_px", sc.drift_threshold_px, [](double x) { return x > 0 && x <= 100; }, "(0, 100] px");
    sc.pattern = s.boolean("pattern", sc.pattern);
    sc.pattern_amplitude = s.number(
        "pattern_amplitude", sc.pattern_amplitude, [](double x) { return x > 0 && x <= 0.2; }, "(0, 0.2]");
}

}  // namespace

ViewerPose start_pose(const NavigationConfig& navigation) {
    ViewerPose pose;
    pose.eye = navigation.start + Eigen::Vector3d(0.0, navigation.eye_height_m, 0.0);
    pose.yaw_deg = navigation.start_yaw_deg;
    pose.pitch_deg = 0.0;
    return pose;
}

bool parse_size(std::string_view text, ImageSize& out) {
    const auto x = text.find('x');
    if (x == std::string_view::npos || x == 0 || x + 1 >= text.size()) return false;
    const auto parse = [](std::string_view digits, int& value) {
        if (digits.empty() || digits.size() > 6) return false;
        for (const char c : digits) {
            if (c < '0' || c > '9') return false;
        }
        const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
        return ec == std::errc() && end == digits.data() + digits.size();
    };
    ImageSize s;
    if (!parse(text.substr(0, x), s.width) || !parse(text.substr(x + 1), s.height)) return false;
    out = s;
    return true;
}

namespace {

Value parse_toml(std::string_view text, const Context& ctx) {
    // toml11 recurses once per level and has no limit: a deep file would crash the kiosk.
    if (const auto excess = toml_nesting_excess(text)) {
        throw KioskConfigError(fmt::format("{}:{}: tables or arrays nested deeper than {} levels", ctx.file,
                                           excess->line, excess->max_depth));
    }
    // toml11 reads out of bounds on a literal string that is not UTF-8 (common/toml_nesting.h).
    if (const auto bad = toml_invalid_utf8(text)) {
        throw KioskConfigError(fmt::format("{}:{}: byte {} of the line is not UTF-8 (TOML files are UTF-8)", ctx.file,
                                           bad->line, bad->column));
    }
    try {
        std::istringstream in{std::string(text)};
        return toml::parse(in, ctx.file);
    } catch (const toml::syntax_error& e) {
        // toml11's message already names the file, line and column, with the offending text.
        throw KioskConfigError(fmt::format("{}: not valid TOML: {}", ctx.file, e.what()));
    } catch (const std::exception& e) {
        throw KioskConfigError(fmt::format("{}: not valid TOML: {}", ctx.file, e.what()));
    }
}

std::string read_config_text(const std::filesystem::path& file) {
    std::error_code ec;
    if (!fs::is_regular_file(file, ec)) {
        throw KioskConfigError(
            fmt::format("{}: {}", file.string(), fs::exists(file, ec) ? "not a regular file" : "no such file"));
    }
    std::ifstream in(file, std::ios::binary);
    if (!in) throw KioskConfigError(fmt::format("{}: cannot open for reading", file.string()));
    std::ostringstream text;
    text << in.rdbuf();
    if (text.str().size() > (1u << 20))
        throw KioskConfigError(fmt::format("{}: larger than 1 MiB, not a kiosk configuration", file.string()));
    return text.str();
}

}  // namespace

OutputsConfig parse_outputs_config(std::string_view text, const std::filesystem::path& name) {
    const Context ctx{name.string(), name.has_parent_path() ? name.parent_path() : fs::path(".")};
    const Value root = parse_toml(text, ctx);
    OutputsConfig outputs;
    const Section display = section(ctx, root, "display", {"rate_hz", "flip_timeout_s"});
    const Section section_outputs =
        section(ctx, root, "outputs", {"backend", "device", "sizes", "png_dir", "png_every", "composite"});
    read_outputs(display, section_outputs, outputs);
    display.finish();
    section_outputs.finish();
    return outputs;
}

OutputsConfig load_outputs_config(const std::filesystem::path& file) {
    return parse_outputs_config(read_config_text(file), file);
}

KioskConfig parse_kiosk_config(std::string_view text, const std::filesystem::path& name) {
    const Context ctx{name.string(), name.has_parent_path() ? name.parent_path() : fs::path(".")};
    const Value root = parse_toml(text, ctx);
    const std::vector<std::string> known_sections{"farm",   "display",    "outputs", "calibration", "quality",
                                                  "screen", "navigation", "stats",   "status",      "selfcal"};
    for (const auto& [key, value] : root.as_table()) {
        if (std::find(known_sections.begin(), known_sections.end(), key) == known_sections.end()) {
            ctx.fail(&value, fmt::format("[{}]: unknown section (known: {})", key, fmt::join(known_sections, ", ")));
        }
    }
    KioskConfig config;
    config.source = name;
    if (root.as_table().count("farm") == 0) {
        ctx.fail(nullptr, "[farm] is required (endpoint, ca, cert, key)");
    }
    const Section farm = section(ctx, root, "farm", {"endpoint", "server_name", "ca", "cert", "key"});
    read_farm(farm, config.farm);
    const Section display = section(ctx, root, "display", {"rate_hz", "flip_timeout_s"});
    const Section outputs =
        section(ctx, root, "outputs", {"backend", "device", "sizes", "png_dir", "png_every", "composite"});
    read_outputs(display, outputs, config.outputs);
    const Section calibration =
        section(ctx, root, "calibration", {"source", "watch", "projectors", "overlap", "output", "gamma"});
    read_calibration(calibration, config.calibration);
    const Section quality =
        section(ctx, root, "quality",
                {"preset", "content", "spp", "jpeg_quality", "bounces", "ao_samples", "area_light_samples"});
    read_quality(quality, config.quality);
    const Section screen = section(ctx, root, "screen", {"radius_m", "arc_deg", "bottom_m", "top_m", "guard_deg"});
    read_screen(screen, config.screen, config.guard_deg);
    check_guarded_width(screen, config);
    const Section navigation = section(ctx, root, "navigation", navigation_keys());
    read_navigation(navigation, config.navigation);
    config.screen.eye_m = Eigen::Vector3d(0.0, config.navigation.eye_height_m, 0.0);
    const Section stats =
        section(ctx, root, "stats", {"file", "log_period_s", "status_file", "status_period_s", "metrics_file"});
    read_stats(stats, config.stats);
    const Section status =
        section(ctx, root, "status", {"on_wall", "trigger_file", "farm_lost_after_s", "certificate_warning_days"});
    read_status(status, config.status);
    const Section selfcal =
        section(ctx, root, "selfcal",
                {"enabled", "camera", "camera_size", "camera_exposure_us", "camera_gain", "models", "rate_hz", "hold_s",
                 "transition_s", "drift_threshold_px", "pattern", "pattern_amplitude"});
    read_selfcal(selfcal, config.calibration, config.selfcal);
    for (const Section* s :
         {&farm, &display, &outputs, &calibration, &quality, &screen, &navigation, &stats, &status, &selfcal})
        s->finish();
    return config;
}

KioskConfig load_kiosk_config(const std::filesystem::path& file) {
    return parse_kiosk_config(read_config_text(file), file);
}

}  // namespace mogao
