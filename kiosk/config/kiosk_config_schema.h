// SPDX-License-Identifier: Apache-2.0
// The kiosk configuration's schema (kiosk.toml, kiosk/config/kiosk_config.h) as one table: one row per
// key with its TOML table, the KioskConfig member it fills, its type, its limits (as checked and as
// messages write them), its default, when it may be written and a one-line description.
//
// The table drives:
//   * the parser (kiosk_config.cpp): every type, range and "only with ..." check of a plain key, in the
//     table's order; the keys whose reading depends on files or other keys (marked `custom`) are read
//     by small named functions there, and the cross-field checks run after the table pass;
//   * the "unknown field (known: ...)" lists (schema_keys);
//   * the reference table of docs/kiosk.md (`mogao-kiosk --print-config-reference`, checked by the
//     CTest kiosk_config_reference_current);
//   * a test that kiosk.example.toml shows every key of the table, and nothing else, with the table's
//     default (KioskConfigSchema.*).
// Defaults are not repeated here: a row's default is the member's value in a default-constructed
// KioskConfig (kiosk_config.h), unless the default depends on other keys (then `default_text` says it).
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "kiosk/config/kiosk_config.h"

namespace mogao {

enum class KeyType {
    boolean,         // true | false
    integer,         // a TOML integer within [lo, hi]
    number,          // an integer or float within `limit`
    string,          // any string
    path,            // a string; empty: none, else resolved against the file's folder
    file,            // an existing regular file, resolved against the file's folder
    size,            // "WIDTHxHEIGHT", each side within [lo, 16384]
    choice,          // one of `choices`
    control,         // a camera control: "auto" | "lock" | "keep" | a number within `limit`
    locked_control,  // a screen camera's control: "lock" | a number within `limit`
    table,           // a sub-table ([navigation.detector]); its keys are rows of their own
    custom,          // read by a named function of the parser (files, other keys)
};

// A number's limit: [lo, hi], an end open when `*_open`; with `or_zero` 0 is accepted too.
struct NumberLimit {
    double lo = 0.0;
    double hi = 0.0;
    bool lo_open = false;
    bool hi_open = false;
    bool or_zero = false;

    [[nodiscard]] bool accepts(double x) const;
};

// When a key may be written. A key written when its condition does not hold is an error
// ("[navigation].path: only with source = \"path\""), except under selfcal_enabled: the [selfcal]
// keys may stay written while it is off.
enum class When {
    always,
    kms,              // [outputs].backend = "kms"
    headless,         // [outputs].backend = "headless"
    ideal,            // [calibration].source = "ideal"
    mpcdi,            // [calibration].source = an MPCDI file
    path_source,      // [navigation].source = "path"
    tracking,         // [navigation].source = "tracking"
    tracking_replay,  //   ... and a "replay:" camera
    tracking_live,    //   ... and a live camera ("v4l2:" or "libcamera:")
    tracking_v4l2,    //   ... and a "v4l2:" camera
    selfcal_enabled,  // [selfcal].enabled = true
    selfcal_v4l2,     //   ... and a "v4l2:" screen camera
};

// The refusal of every [navigation] tracking key while source = "path".
inline constexpr std::string_view kOnlyWithTracking = "with source = \"tracking\"";

// Where a row's value goes: a reference to the member in a KioskConfig.
struct ChoiceMember {
    std::size_t (*get)(const KioskConfig&);
    void (*set)(KioskConfig&, std::size_t);
};
using Member =
    std::variant<std::monostate, bool& (*)(KioskConfig&), int& (*)(KioskConfig&), double& (*)(KioskConfig&),
                 float& (*)(KioskConfig&), std::string& (*)(KioskConfig&), std::filesystem::path& (*)(KioskConfig&),
                 ImageSize& (*)(KioskConfig&), ControlSetting& (*)(KioskConfig&), ChoiceMember>;

struct ConfigKey {
    std::string_view table;  // "farm", "navigation.detector"
    std::string_view key;
    KeyType type;
    Member member{};           // monostate for table and custom rows
    NumberLimit limit{};       // integer, number, control: the accepted values; size: lo = least side
    std::string_view range{};  // the limit as messages and docs write it ("[0.5, 240] Hz")
    std::span<const std::string_view> choices{};  // choice: the accepted strings, in the member's enum order
    std::string_view default_text{};              // empty: the member's value in KioskConfig{}; else as written here
    When when = When::always;
    std::string_view only{};      // the refusal when `when` does not hold: "with backend = \"headless\""
    std::string_view required{};  // required (when `when` holds): what the key must name
    std::string_view doc{};       // one line
    ControlSetting::Mode control_default = ControlSetting::Mode::keep;  // control: when absent
    double control_value = 0.0;                                         // control: manual default
    bool selects = false;  // other rows' `when` depends on it: read before the table's other keys
};

// The rows, grouped by table in the file's order ([farm] ... [selfcal]); a key may have one row per
// mode ([navigation].camera_fps: replay and v4l2).
[[nodiscard]] std::span<const ConfigKey> kiosk_config_schema();

// The tables a kiosk.toml may have at its top level, in order.
[[nodiscard]] std::vector<std::string> schema_sections();

// The keys of `table` in the table's order, each once (the "known:" list of messages).
[[nodiscard]] std::vector<std::string> schema_keys(std::string_view table);

// A row's default as written in the file (`"kms"`, `30`, `[0, 0, 5]`), or its default_text.
[[nodiscard]] std::string schema_default(const ConfigKey& row);

// The Markdown reference table of every key (docs/kiosk.md's generated block, without its markers).
[[nodiscard]] std::string config_reference_markdown();

}  // namespace mogao
