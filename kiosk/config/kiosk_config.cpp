// SPDX-License-Identifier: Apache-2.0
// The parser: one pass over the schema's rows (kiosk_config_schema.h) per table, in the table's order.
// A plain row is read, range-checked and stored by its type; a row written where its `when` does not
// hold is refused; a `custom` row is read by a named function below. Cross-field checks run after the
// pass of their table.
#include "kiosk/config/kiosk_config.h"

#include <algorithm>
#include <span>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "appliance/tracker/tag_family.h"
#include "appliance/warp/late_warp.h"
#include "common/quality_preset.h"
#include "common/request_limits.h"
#include "kiosk/config/kiosk_config_schema.h"
#include "kiosk/config/kiosk_config_section.h"
#include "renderfarm/link/endpoint.h"

namespace mogao {
namespace {

using kiosk_config::Context;
using kiosk_config::context_of;
using kiosk_config::parse_toml;
using kiosk_config::read_config_text;
using kiosk_config::Section;
using kiosk_config::type_name;
using kiosk_config::Value;
namespace fs = std::filesystem;

[[noreturn]] void fail_required(const Section& s, const ConfigKey& row) {
    s.fail(nullptr, row.key, fmt::format(" is required ({})", row.required));
}

// --- the custom rows: keys whose reading depends on files or on other keys ---------------------

void read_endpoint(const Section& s, const ConfigKey& row, const Value* v, KioskConfig& c) {
    if (v == nullptr) fail_required(s, row);
    std::string& endpoint = c.farm.endpoint;
    endpoint = s.as_string(*v, row.key);
    std::string why;
    const auto parsed = parse_endpoint(endpoint, &why);
    if (!parsed) s.fail(v, row.key, ": " + why);
    if (parsed->port == 0) s.fail(v, row.key, fmt::format(": '{}' has port 0 (the farm's port is 1..65535)", endpoint));
    if (parsed->is_wildcard()) s.fail(v, row.key, fmt::format(": '{}' is the wildcard address, not a farm", endpoint));
}

void read_sizes(const Section& s, const ConfigKey& row, const Value* v, KioskConfig& c) {
    if (v == nullptr) return;
    if (!v->is_array()) s.fail(v, row.key, ": expected an array of \"WIDTHxHEIGHT\" strings, got " + type_name(*v));
    const auto& list = v->as_array();
    if (list.empty() || list.size() > 64)
        s.fail(v, row.key, fmt::format(": {} outputs is outside [1, 64]", list.size()));
    for (std::size_t i = 0; i < list.size(); ++i) {
        c.outputs.sizes.push_back(s.as_size(list[i], fmt::format("{}[{}]", row.key, i), 1));
    }
}

void read_calibration_source(const Section& s, const ConfigKey& row, const Value* v, KioskConfig& c) {
    if (v != nullptr && s.as_string(*v, row.key) != "ideal") c.calibration.mpcdi = s.existing_file(*v, row.key);
}

// A preset (common/quality_preset.h, the farm's table); the explicit keys after it override it.
void read_preset(const Section& s, const ConfigKey& row, const Value* v, KioskConfig& c) {
    if (v == nullptr) return;
    const std::string name = s.as_string(*v, row.key);
    const QualityPreset* p = quality_preset(name);
    if (p == nullptr) s.fail(v, row.key, fmt::format(": '{}' is not one of {}", name, quality_preset_names()));
    QualityConfig& q = c.quality;
    q.preset = name;
    q.spp = p->request.spp;
    q.jpeg_quality = p->request.jpeg_quality;
    q.max_bounces = p->request.max_bounces;
    q.ao_samples = p->request.ao_samples;
    q.area_light_samples = p->request.area_light_samples;
}

// The late warp's guard band (appliance/warp/late_warp.h): the widened arc must stay a cylinder.
void read_guard(const Section& s, const ConfigKey& row, const Value* v, KioskConfig& c) {
    if (v == nullptr) return;
    const double max_guard = (360.0 - c.screen.arc_deg) / 2.0;
    c.guard_deg = s.as_number(*v, row.key, {0.0, max_guard},
                              fmt::format("[0, {}] degrees: arc_deg + 2 * guard_deg <= 360", max_guard));
}

void read_path(const Section& s, const ConfigKey& row, const Value* v, KioskConfig& c) {
    if (v == nullptr) return;
    const std::string text = s.as_string(*v, row.key);
    if (text == "walk" || text == "orbit") {
        c.navigation.path = text;
    } else if (text.empty()) {
        s.fail(v, row.key, ": empty (expected walk, orbit or a JSON path file)");
    } else {
        c.navigation.path = s.existing_file(*v, row.key).string();
    }
}

void read_start(const Section& s, const ConfigKey& row, const Value* v, KioskConfig& c) {
    if (v == nullptr) return;
    if (!v->is_array() || v->as_array().size() != 3) {
        s.fail(v, row.key, ": expected [x, y, z] (floor point of the viewer's start, metres)");
    }
    for (std::size_t i = 0; i < 3; ++i) {
        c.navigation.start[static_cast<Eigen::Index>(i)] =
            s.as_number(v->as_array()[i], fmt::format("{}[{}]", row.key, i), {-1e9, 1e9}, "[-1e9, 1e9] m");
    }
}

void read_tracking_camera(const Section& s, const ConfigKey& row, const Value* v, KioskConfig& c) {
    if (v == nullptr) fail_required(s, row);
    TrackingConfig& t = c.navigation.tracking;
    t.camera = s.as_string(*v, row.key);
    std::string why;
    if (!parse_camera_source(t.camera, t.source, &why)) s.fail(v, row.key, ": " + why);
    if (t.source.kind == CameraSourceSpec::Kind::replay) {
        t.source.folder = s.context().resolve(t.source.folder.string());
        std::error_code ec;
        if (!fs::is_directory(t.source.folder, ec)) {
            s.fail(v, row.key, fmt::format(": replay folder '{}' does not exist", t.source.folder.string()));
        }
    } else if (t.source.kind == CameraSourceSpec::Kind::v4l2 && !fs::path(t.source.device).is_absolute()) {
        s.fail(v, row.key,
               fmt::format(": '{}' is not an absolute device path (\"v4l2:/dev/videoN\")", t.source.device));
    }
}

// [navigation].camera_size is read with the intrinsics (its default is their size).
void read_nothing(const Section&, const ConfigKey&, const Value*, KioskConfig&) {}

void read_intrinsics_key(const Section& s, const ConfigKey& row, const Value* v, KioskConfig& c) {
    TrackingConfig& t = c.navigation.tracking;
    const bool replay = t.source.kind == CameraSourceSpec::Kind::replay;
    if (v != nullptr) {
        t.intrinsics_file = s.existing_file(*v, row.key);
    } else if (replay && fs::exists(t.source.folder / "camera.json")) {
        t.intrinsics_file = t.source.folder / "camera.json";
    } else {
        s.fail(nullptr, row.key,
               replay ? fmt::format(" is required (the camera calibration, JSON or OpenCV YAML; "
                                    "'{}' has no camera.json)",
                                    t.source.folder.string())
                      : std::string(" is required with a live camera (\"v4l2:\" or \"libcamera:\"; "
                                    "the camera calibration, JSON or OpenCV YAML)"));
    }
    try {
        t.intrinsics = read_intrinsics(t.intrinsics_file);
    } catch (const std::exception& e) {
        s.fail(v, row.key, fmt::format(": {}", e.what()));
    }
    if (replay) return;
    const ImageSize calibrated{t.intrinsics.width, t.intrinsics.height};
    const Value* written = s.find("camera_size");
    const ImageSize size = written == nullptr ? calibrated : s.as_size(*written, "camera_size", 1);
    if (size.width > 8192 || size.height > 8192)
        s.fail(written, "camera_size", " is outside [1, 8192] pixels per side");
    if (size.width != calibrated.width || size.height != calibrated.height) {
        t.intrinsics = rescale(t.intrinsics, size.width, size.height);  // a binned mode of the calibrated sensor
    }
    t.source.width = size.width;
    t.source.height = size.height;
}

void read_trigger_file(const Section& s, const ConfigKey& row, const Value* v, KioskConfig& c) {
    const std::string trigger = v == nullptr ? "" : s.as_string(*v, row.key);
    if (trigger.empty()) return;
    if (c.status.on_wall != OnWall::on_demand) s.fail(v, row.key, fmt::format(": only {}", row.only));
    c.status.trigger_file = s.context().resolve(trigger);
}

void read_selfcal_enabled(const Section& s, const ConfigKey& row, const Value* v, KioskConfig& c) {
    c.selfcal.enabled = v != nullptr && s.as_boolean(*v, row.key);
    if (c.selfcal.enabled && c.calibration.mpcdi.empty()) {
        s.fail(v, row.key,
               " = true needs [calibration].source to be an MPCDI file (the fitted calibration that "
               "self-recalibration corrects and writes back), not \"ideal\"");
    }
}

void read_selfcal_camera(const Section& s, const ConfigKey& row, const Value* v, KioskConfig& c) {
    if (v == nullptr) fail_required(s, row);
    SelfcalConfig& sc = c.selfcal;
    sc.camera = s.as_string(*v, row.key);
    const std::string_view text = sc.camera;
    if (text.starts_with("rig:")) {
        sc.kind = SelfcalConfig::CameraKind::rig;
        const std::string file(text.substr(4));
        if (file.empty()) s.fail(v, row.key, ": \"rig:\" needs the virtual rig's file (rig:<rig.toml>)");
        sc.rig = s.context().resolve(file);
        std::error_code ec;
        if (!fs::is_regular_file(sc.rig, ec)) {
            s.fail(v, row.key, fmt::format(": rig file '{}' does not exist", sc.rig.string()));
        }
        return;
    }
    std::string why;
    if (!text.starts_with("v4l2:") || !parse_camera_source(sc.camera, sc.source, &why)) {
        s.fail(v, row.key, fmt::format(": '{}' is not \"v4l2:/dev/videoN\" or \"rig:<rig.toml>\"", sc.camera));
    }
    sc.kind = SelfcalConfig::CameraKind::v4l2;
    if (!fs::path(sc.source.device).is_absolute()) {
        s.fail(v, row.key, fmt::format(": '{}' is not an absolute device path", sc.source.device));
    }
}

void read_selfcal_size(const Section& s, const ConfigKey& row, const Value* v, KioskConfig& c) {
    const ImageSize size = v == nullptr ? ImageSize{0, 0} : s.as_size(*v, row.key, 1);
    c.selfcal.source.width = size.width;  // 0: the models' camera resolution (kiosk_setup)
    c.selfcal.source.height = size.height;
}

void read_models(const Section& s, const ConfigKey& row, const Value* v, KioskConfig& c) {
    SelfcalConfig& sc = c.selfcal;
    if (v != nullptr) {
        sc.models = s.existing_file(*v, row.key);
        return;
    }
    sc.models = c.calibration.mpcdi;
    sc.models.replace_extension(".models.json");  // autocal::models_path_for
    std::error_code ec;
    if (!fs::is_regular_file(sc.models, ec)) {
        s.fail(nullptr, row.key,
               fmt::format(" is required: '{}' (beside the MPCDI, written by mogao-calibrate) does not exist",
                           sc.models.string()));
    }
}

using CustomReader = void (*)(const Section&, const ConfigKey&, const Value*, KioskConfig&);
struct Custom {
    std::string_view table;
    std::string_view key;
    CustomReader read;
};
const Custom kCustom[] = {
    {"farm", "endpoint", read_endpoint},
    {"outputs", "sizes", read_sizes},
    {"calibration", "source", read_calibration_source},
    {"quality", "preset", read_preset},
    {"screen", "guard_deg", read_guard},
    {"navigation", "path", read_path},
    {"navigation", "start", read_start},
    {"navigation", "camera", read_tracking_camera},
    {"navigation", "camera_size", read_nothing},
    {"navigation", "intrinsics", read_intrinsics_key},
    {"status", "trigger_file", read_trigger_file},
    {"selfcal", "enabled", read_selfcal_enabled},
    {"selfcal", "camera", read_selfcal_camera},
    {"selfcal", "camera_size", read_selfcal_size},
    {"selfcal", "models", read_models},
};

// --- the plain rows --------------------------------------------------------------------------

// One camera control key: "auto", "lock", "keep" or a number within the row's limit (the device's
// own range is checked when the camera opens; the setting carries the key's name for that message).
// Written: required (a camera without the control is an error); absent: the row's default.
ControlSetting read_control_setting(const Section& s, const ConfigKey& row, const Value* v) {
    ControlSetting setting{row.control_default, row.control_value, false, ""};
    setting.name = fmt::format("{}: {}", s.context().file, s.field(row.key));
    if (v == nullptr) return setting;
    setting.required = true;
    if (!v->is_string()) {
        setting.mode = ControlSetting::Mode::manual;
        setting.value = s.as_number(*v, row.key, row.limit, row.range);
        return setting;
    }
    const std::string text = v->as_string().str;
    if (text == "auto") {
        setting.mode = ControlSetting::Mode::automatic;
    } else if (text == "lock") {
        setting.mode = ControlSetting::Mode::lock;
    } else if (text == "keep") {
        setting.mode = ControlSetting::Mode::keep;
    } else {
        s.fail(v, row.key, fmt::format(": '{}' is not one of auto, lock, keep or a number in {}", text, row.range));
    }
    return setting;
}

// A screen camera's exposure or gain: "lock" (default: hold what the automatic loop reached) or a
// manual value; never automatic, never left as the device has it (the monitor compares frames
// taken minutes apart: a camera re-metering each frame would change what it sees).
ControlSetting read_locked_control(const Section& s, const ConfigKey& row, const Value* v) {
    ControlSetting setting = read_control_setting(s, row, v);
    setting.required = true;  // a screen camera without the control cannot be trusted to hold still
    if (setting.mode == ControlSetting::Mode::automatic || setting.mode == ControlSetting::Mode::keep) {
        s.fail(v, row.key,
               fmt::format(": the screen camera's {} must be \"lock\" or a value in {}", row.key, row.range));
    }
    return setting;
}

void read_choice(const Section& s, const ConfigKey& row, const Value& v, KioskConfig& c) {
    const std::string text = s.as_string(v, row.key);
    const auto it = std::find(row.choices.begin(), row.choices.end(), text);
    if (it == row.choices.end()) {
        s.fail(&v, row.key, fmt::format(": '{}' is not one of {}", text, fmt::join(row.choices, ", ")));
    }
    std::get<ChoiceMember>(row.member).set(c, static_cast<std::size_t>(it - row.choices.begin()));
}

void read_number(const Section& s, const ConfigKey& row, const Value& v, KioskConfig& c) {
    const double x = s.as_number(v, row.key, row.limit, row.range);
    if (const auto* member = std::get_if<float& (*)(KioskConfig&)>(&row.member)) {
        (*member)(c) = static_cast<float>(x);
    } else {
        std::get<double& (*)(KioskConfig&)>(row.member)(c) = x;
    }
}

template <class T>
T& member(const ConfigKey& row, KioskConfig& c) {
    return std::get<T& (*)(KioskConfig&)>(row.member)(c);
}

void read_table(const Section& s, KioskConfig& c);

void read_row(const Section& s, const ConfigKey& row, const Value* v, KioskConfig& c) {
    if (row.type == KeyType::control) {
        member<ControlSetting>(row, c) = read_control_setting(s, row, v);
        return;
    }
    if (row.type == KeyType::locked_control) {
        member<ControlSetting>(row, c) = read_locked_control(s, row, v);
        return;
    }
    if (v == nullptr) {
        if (!row.required.empty()) fail_required(s, row);
        return;
    }
    const auto lo = static_cast<int>(row.limit.lo);
    switch (row.type) {
        case KeyType::boolean:
            member<bool>(row, c) = s.as_boolean(*v, row.key);
            return;
        case KeyType::integer:
            member<int>(row, c) = s.as_integer(*v, row.key, lo, static_cast<int>(row.limit.hi));
            return;
        case KeyType::number:
            return read_number(s, row, *v, c);
        case KeyType::string:
            member<std::string>(row, c) = s.as_string(*v, row.key);
            return;
        case KeyType::path:
            if (const std::string text = s.as_string(*v, row.key); !text.empty())
                member<fs::path>(row, c) = s.context().resolve(text);
            return;
        case KeyType::file:
            member<fs::path>(row, c) = s.existing_file(*v, row.key);
            return;
        case KeyType::size:
            member<ImageSize>(row, c) = s.as_size(*v, row.key, lo);
            return;
        case KeyType::choice:
            return read_choice(s, row, *v, c);
        default:
            throw std::logic_error(fmt::format("kiosk config schema: {} has no reader", s.field(row.key)));
    }
}

// --- cross-field checks, after a table's pass ---------------------------------------------------

void check_screen(const Section& s, const KioskConfig& c) {
    if (!(c.screen.top_m > c.screen.bottom_m)) {
        s.fail(s.find("top_m") != nullptr ? s.find("top_m") : s.find("bottom_m"), "top_m",
               fmt::format(" = {} must be above [screen].bottom_m = {}", c.screen.top_m, c.screen.bottom_m));
    }
    // The guarded frame the farm is asked for must fit the link's image limit.
    const auto guarded = guard_band(c.screen, c.quality.content, c.guard_deg);
    if (!guarded) s.fail(s.find("guard_deg"), "guard_deg", ": " + guarded.error().message);
    if (guarded->size.width > request_limits::kLinkImageSide.max) {
        s.fail(s.find("guard_deg"), "guard_deg",
               fmt::format(" = {} widens [quality].content to {} columns, beyond the link's {}", c.guard_deg,
                           guarded->size.width, request_limits::kLinkImageSide.max));
    }
}

void check_detector(const Section& s, const DetectorSettings& d) {
    const auto& families = TagFamily::known_names();
    if (std::find(families.begin(), families.end(), d.family) == families.end()) {
        s.fail(s.find("family"), "family", fmt::format(": '{}' is not one of {}", d.family, fmt::join(families, ", ")));
    }
    try {
        validate(d);
    } catch (const std::invalid_argument& e) {
        s.context().fail(nullptr, fmt::format("[{}]: {}", s.name(), e.what()));
    }
}

void check_control(const Section& s, const NavigationParams& p) {
    try {
        validate(p);  // the relations: full scale above dead zone, hold_s <= forget_s
    } catch (const std::invalid_argument& e) {
        s.context().fail(nullptr, fmt::format("[{}]: {}", s.name(), e.what()));
    }
}

// [navigation.detector], [navigation.roi], [navigation.control]: a pass of their own, then their checks.
void read_subtable(const Section& parent, const ConfigKey& row, KioskConfig& c) {
    const Section sub = kiosk_config::subsection(parent, row.key);
    TrackingConfig& t = c.navigation.tracking;
    t.params.eye_height_m = c.navigation.eye_height_m;
    read_table(sub, c);
    if (row.key == "detector") check_detector(sub, t.detector);
    if (row.key == "control") check_control(sub, t.params);
    sub.finish();
}

void after_navigation(KioskConfig& c) {
    TrackingConfig& t = c.navigation.tracking;
    t.params.eye_height_m = c.navigation.eye_height_m;
    t.source.loop = t.source.kind == CameraSourceSpec::Kind::replay && t.replay_end == ReplayEnd::loop;
    c.screen.eye_m = Eigen::Vector3d(0.0, c.navigation.eye_height_m, 0.0);
}

// --- the pass ------------------------------------------------------------------------------------

// Whether `row` applies to `c` as read so far; if not, the refusal of a written key ("" = none: the
// key is left unread, as [selfcal]'s keys while it is off).
struct Verdict {
    bool applies;
    std::string_view refusal;
};

Verdict judge(const ConfigKey& row, const KioskConfig& c) {
    const auto kind = c.navigation.tracking.source.kind;
    const bool tracking = c.navigation.source == NavigationSource::tracking;
    switch (row.when) {
        case When::always:
            return {true, {}};
        case When::kms:
        case When::headless:
            return {(c.outputs.backend == OutputKind::kms) == (row.when == When::kms), row.only};
        case When::ideal:
        case When::mpcdi:
            return {c.calibration.mpcdi.empty() == (row.when == When::ideal), row.only};
        case When::path_source:
            return {!tracking, row.only};
        case When::tracking:
            return {tracking, row.only};
        case When::tracking_replay:
        case When::tracking_live:
        case When::tracking_v4l2:
            if (!tracking) return {false, kOnlyWithTracking};
            if (row.when == When::tracking_replay) return {kind == CameraSourceSpec::Kind::replay, row.only};
            if (row.when == When::tracking_v4l2) return {kind == CameraSourceSpec::Kind::v4l2, row.only};
            return {kind != CameraSourceSpec::Kind::replay, row.only};
        case When::selfcal_enabled:
            return {c.selfcal.enabled, {}};
        case When::selfcal_v4l2:
            if (!c.selfcal.enabled) return {false, {}};
            return {c.selfcal.kind == SelfcalConfig::CameraKind::v4l2, row.only};
    }
    return {false, row.only};
}

void dispatch(const Section& s, const ConfigKey& row, const Value* v, KioskConfig& c) {
    if (row.type == KeyType::table) return read_subtable(s, row, c);
    if (row.type != KeyType::custom) return read_row(s, row, v, c);
    for (const Custom& custom : kCustom) {
        if (custom.table == row.table && custom.key == row.key) return custom.read(s, row, v, c);
    }
    throw std::logic_error(fmt::format("kiosk config schema: {} has no reader", s.field(row.key)));
}

// The rows of one key: one, or one per mode ([navigation].camera_fps).
using KeyRows = std::span<const ConfigKey>;

std::vector<KeyRows> keys_of(std::string_view table) {
    const auto rows = kiosk_config_schema();
    std::vector<KeyRows> keys;
    for (std::size_t i = 0; i < rows.size(); ++i) {
        if (rows[i].table != table) continue;
        std::size_t end = i + 1;
        while (end < rows.size() && rows[end].table == table && rows[end].key == rows[i].key) ++end;
        keys.push_back(rows.subspan(i, end - i));
        i = end - 1;
    }
    return keys;
}

// The first row that applies, and otherwise the last one's refusal.
std::pair<const ConfigKey*, std::string_view> choose(KeyRows rows, const KioskConfig& c) {
    std::string_view refusal;
    for (const ConfigKey& row : rows) {
        const Verdict verdict = judge(row, c);
        if (verdict.applies) return {&row, {}};
        refusal = verdict.refusal;
    }
    return {nullptr, refusal};
}

// A table's pass: first the keys that select a mode (backend, source, camera, ...), then the refusal
// of every written key whose mode does not hold, then the other keys, each in the table's order.
void read_table(const Section& s, KioskConfig& c) {
    const std::vector<KeyRows> keys = keys_of(s.name());
    const auto read = [&](KeyRows rows) {
        if (const auto [row, refusal] = choose(rows, c); row != nullptr) dispatch(s, *row, s.find(row->key), c);
    };
    for (const KeyRows& rows : keys) {
        if (rows.front().selects) read(rows);
    }
    for (const KeyRows& rows : keys) {
        const Value* v = s.find(rows.front().key);
        const auto [row, refusal] = choose(rows, c);
        if (row == nullptr && v != nullptr && !refusal.empty()) {
            s.fail(v, rows.front().key, fmt::format(": only {}", refusal));
        }
    }
    for (const KeyRows& rows : keys) {
        if (!rows.front().selects) read(rows);
    }
}

}  // namespace

ViewerPose start_pose(const NavigationConfig& navigation) {
    ViewerPose pose;
    pose.eye = navigation.start + Eigen::Vector3d(0.0, navigation.eye_height_m, 0.0);
    pose.yaw_deg = navigation.start_yaw_deg;
    pose.pitch_deg = 0.0;
    return pose;
}

OutputsConfig parse_outputs_config(std::string_view text, const std::filesystem::path& name) {
    const Context ctx = context_of(name);
    const Value root = parse_toml(text, ctx);
    KioskConfig config;
    const Section display = kiosk_config::section(ctx, root, "display");
    const Section outputs = kiosk_config::section(ctx, root, "outputs");
    read_table(display, config);
    read_table(outputs, config);
    display.finish();
    outputs.finish();
    return config.outputs;
}

OutputsConfig load_outputs_config(const std::filesystem::path& file) {
    return parse_outputs_config(read_config_text(file), file);
}

KioskConfig parse_kiosk_config(std::string_view text, const std::filesystem::path& name) {
    const Context ctx = context_of(name);
    const Value root = parse_toml(text, ctx);
    const std::vector<std::string> known_sections = schema_sections();
    for (const auto& [key, value] : root.as_table()) {
        if (std::find(known_sections.begin(), known_sections.end(), key) == known_sections.end()) {
            ctx.fail(&value, fmt::format("[{}]: unknown section (known: {})", key, fmt::join(known_sections, ", ")));
        }
    }
    if (root.as_table().count("farm") == 0) ctx.fail(nullptr, "[farm] is required (endpoint, ca, cert, key)");
    KioskConfig config;
    config.source = name;
    std::vector<Section> sections;
    sections.reserve(known_sections.size());
    for (const std::string& table : known_sections) {
        const Section& s = sections.emplace_back(kiosk_config::section(ctx, root, table));
        read_table(s, config);
        if (table == "screen") check_screen(s, config);
        if (table == "navigation") after_navigation(config);
    }
    for (const Section& s : sections) s.finish();
    return config;
}

KioskConfig load_kiosk_config(const std::filesystem::path& file) {
    return parse_kiosk_config(read_config_text(file), file);
}

}  // namespace mogao
