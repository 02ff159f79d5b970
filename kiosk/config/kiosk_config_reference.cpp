// SPDX-License-Identifier: Apache-2.0
// The schema's defaults as written in a file, and its Markdown reference (kiosk_config_schema.h).
#include <fmt/format.h>

#include "kiosk/config/kiosk_config_schema.h"

namespace mogao {
namespace {

template <class... F>
struct Overloaded : F... {
    using F::operator()...;
};
template <class... F>
Overloaded(F...) -> Overloaded<F...>;

// The member's value in `c` as TOML.
std::string member_value(const ConfigKey& row, KioskConfig& c) {
    return std::visit(
        Overloaded{
            [](std::monostate) { return std::string("—"); },
            [&](bool& (*m)(KioskConfig&)) { return std::string(m(c) ? "true" : "false"); },
            [&](int& (*m)(KioskConfig&)) { return fmt::format("{}", m(c)); },
            [&](double& (*m)(KioskConfig&)) { return fmt::format("{}", m(c)); },
            [&](float& (*m)(KioskConfig&)) { return fmt::format("{}", static_cast<double>(m(c))); },
            [&](std::string& (*m)(KioskConfig&)) { return fmt::format("\"{}\"", m(c)); },
            [&](std::filesystem::path& (*m)(KioskConfig&)) {
                return m(c).empty() ? std::string("none") : fmt::format("\"{}\"", m(c).string());
            },
            [&](ImageSize& (*m)(KioskConfig&)) { return fmt::format("\"{}x{}\"", m(c).width, m(c).height); },
            [&](ControlSetting& (*)(KioskConfig&)) {
                switch (row.control_default) {
                    case ControlSetting::Mode::manual:
                        return fmt::format("{}", row.control_value);
                    case ControlSetting::Mode::lock:
                        return std::string("\"lock\"");
                    case ControlSetting::Mode::automatic:
                        return std::string("\"auto\"");
                    case ControlSetting::Mode::keep:
                        break;
                }
                return std::string("\"keep\"");
            },
            [&](const ChoiceMember& m) { return fmt::format("\"{}\"", row.choices[m.get(c)]); },
        },
        row.member);
}

std::string type_text(const ConfigKey& row) {
    switch (row.type) {
        case KeyType::boolean:
            return "boolean";
        case KeyType::integer:
            return "integer";
        case KeyType::number:
            return "number";
        case KeyType::string:
            return "string";
        case KeyType::path:
            return "path";
        case KeyType::file:
            return "existing file";
        case KeyType::size:
            return "\"WxH\"";
        case KeyType::choice:
            return "string";
        case KeyType::control:
            return "`\"auto\"`, `\"lock\"`, `\"keep\"` or a number";
        case KeyType::locked_control:
            return "`\"lock\"` or a number";
        case KeyType::table:
            return "table";
        case KeyType::custom:
            break;
    }
    return "see limits";
}

std::string limits_text(const ConfigKey& row) {
    switch (row.type) {
        case KeyType::integer:
            return fmt::format("[{}, {}]", row.limit.lo, row.limit.hi);
        case KeyType::size:
            return fmt::format("[{}, 16384] pixels per side", row.limit.lo);
        case KeyType::choice: {
            std::string text;
            for (const std::string_view choice : row.choices)
                text += fmt::format("{}`\"{}\"`", text.empty() ? "" : ", ", choice);
            return text;
        }
        default:
            return std::string(row.range);
    }
}

std::string when_text(const ConfigKey& row) {
    std::string text;
    switch (row.when) {
        case When::always:
            break;
        case When::tracking_replay:
        case When::tracking_live:
        case When::tracking_v4l2:
            text = fmt::format("{}; {}", kOnlyWithTracking, row.only);
            break;
        case When::selfcal_enabled:
            text = "with enabled = true";
            break;
        case When::selfcal_v4l2:
            text = fmt::format("with enabled = true; {}", row.only);
            break;
        default:
            text = std::string(row.only);
    }
    if (!row.required.empty()) text += text.empty() ? "required" : ", required";
    return text;
}

// Markdown cell: no pipes, no line breaks.
std::string cell(std::string text) {
    std::string out;
    for (const char ch : text) out += ch == '|' ? std::string("\\|") : std::string(1, ch);
    return out;
}

}  // namespace

std::string schema_default(const ConfigKey& row) {
    if (!row.default_text.empty()) return std::string(row.default_text);
    if (!row.required.empty()) return "—";
    KioskConfig defaults;
    return member_value(row, defaults);
}

std::string config_reference_markdown() {
    std::string out =
        "| key | type | default | limits | only / required | meaning |\n"
        "|---|---|---|---|---|---|\n";
    for (const ConfigKey& row : kiosk_config_schema()) {
        const std::string def = row.default_text.empty() && row.required.empty() && row.type != KeyType::table
                                    ? fmt::format("`{}`", schema_default(row))
                                    : schema_default(row);
        out += fmt::format("| `[{}] {}` | {} | {} | {} | {} | {} |\n", row.table, row.key, cell(type_text(row)),
                           cell(def), cell(limits_text(row)), cell(when_text(row)), cell(std::string(row.doc)));
    }
    return out;
}

}  // namespace mogao
