// SPDX-License-Identifier: Apache-2.0
#include "kiosk/config/config_overrides.h"

#include <cctype>
#include <fstream>
#include <optional>
#include <sstream>

#include <fmt/format.h>
#include <toml.hpp>

#include "common/toml_nesting.h"

namespace mogao {
namespace {

bool is_name_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_'; }

// "# x" -> "x": commented-out lines of the example start with exactly "# ".
std::string_view uncommented(std::string_view line, bool* commented) {
    *commented = line.rfind("# ", 0) == 0;
    return *commented ? line.substr(2) : line;
}

// The table a line opens ("[a.b]" or "# [a.b]", maybe with a trailing comment), or nullopt.
std::optional<std::string> header_of(std::string_view line, bool* commented) {
    line = uncommented(line, commented);
    const auto close = line.find(']');
    if (line.empty() || line[0] != '[' || close == std::string_view::npos || close == 1) return std::nullopt;
    const std::string_view name = line.substr(1, close - 1);
    for (const char c : name) {
        if (!is_name_char(c) && c != '.') return std::nullopt;
    }
    return std::string(name);
}

// The key a line sets ("key = ..." or "# key = ..."), or nullopt.
std::optional<std::string> key_of(std::string_view line, bool* commented) {
    line = uncommented(line, commented);
    std::size_t n = 0;
    while (n < line.size() && is_name_char(line[n])) ++n;
    if (n == 0 || line.substr(n).rfind(" = ", 0) != 0) return std::nullopt;
    return std::string(line.substr(0, n));
}

struct Override {
    std::string section;
    std::string key;
    std::string value;  // empty: comment the key out
};

Override parse_override(const std::string& text) {
    const auto eq = text.find('=');
    const auto dot = text.rfind('.', eq);
    if (eq == std::string::npos || dot == std::string::npos || dot == 0 || dot + 1 == eq) {
        throw KioskConfigError(fmt::format("override '{}': expected section.key=VALUE", text));
    }
    Override o{text.substr(0, dot), text.substr(dot + 1, eq - dot - 1), text.substr(eq + 1)};
    if (o.value.find('\n') != std::string::npos) {
        throw KioskConfigError(fmt::format("override '{}': the value must be one line", text));
    }
    return o;
}

std::vector<std::string> split_lines(std::string_view text) {
    std::vector<std::string> lines;
    std::istringstream in{std::string(text)};
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
}

// Index of the section's header (uncommented if it was commented out and `open` is set).
std::size_t find_section(std::vector<std::string>& lines, const Override& o, const std::string& text, bool open) {
    std::optional<std::size_t> commented_at;
    for (std::size_t i = 0; i < lines.size(); ++i) {
        bool commented = false;
        if (header_of(lines[i], &commented) != o.section) continue;
        if (!commented) return i;
        if (!commented_at) commented_at = i;
    }
    if (!commented_at)
        throw KioskConfigError(fmt::format("override '{}': no section [{}] in the example", text, o.section));
    if (open) lines[*commented_at] = lines[*commented_at].substr(2);
    return *commented_at;
}

void apply(std::vector<std::string>& lines, const std::string& text) {
    const Override o = parse_override(text);
    const std::size_t header = find_section(lines, o, text, !o.value.empty());
    std::optional<std::size_t> set_at;
    std::optional<std::size_t> commented_at;
    for (std::size_t i = header + 1; i < lines.size() && !set_at; ++i) {
        bool commented = false;
        if (header_of(lines[i], &commented)) break;  // the next table, even a commented-out one
        if (key_of(lines[i], &commented) != o.key) continue;
        if (!commented) set_at = i;
        else if (!commented_at) commented_at = i;
    }
    if (!set_at && !commented_at) {
        throw KioskConfigError(
            fmt::format("override '{}': [{}] has no field '{}' in the example", text, o.section, o.key));
    }
    if (o.value.empty()) {
        if (set_at) lines[*set_at] = "# " + lines[*set_at];
        return;
    }
    lines[set_at ? *set_at : *commented_at] = o.key + " = " + o.value;
}

std::string join(const std::vector<std::string>& lines) {
    std::string out;
    for (const auto& line : lines) out += line + "\n";
    return out;
}

}  // namespace

std::string apply_config_overrides(std::string_view toml, const std::vector<std::string>& overrides) {
    std::vector<std::string> lines = split_lines(toml);
    for (const std::string& text : overrides) {
        apply(lines, text);
        const std::string joined = join(lines);
        if (const auto excess = toml_nesting_excess(joined)) {
            throw KioskConfigError(fmt::format("override '{}': line {} nests tables or arrays deeper than {} levels",
                                               text, excess->line, excess->max_depth));
        }
        if (const auto bad = toml_invalid_utf8(joined)) {
            throw KioskConfigError(
                fmt::format("override '{}': line {} is not UTF-8 (byte {})", text, bad->line, bad->column));
        }
        std::istringstream in(joined);
        try {
            (void)toml::parse(in, "kiosk.example.toml");
        } catch (const std::exception& e) {
            throw KioskConfigError(fmt::format("override '{}': the result is not valid TOML: {}", text, e.what()));
        }
    }
    return join(lines);
}

std::vector<std::string> expand_override_files(const std::vector<std::string>& args) {
    std::vector<std::string> out;
    for (const std::string& arg : args) {
        if (arg.rfind('@', 0) != 0) {
            out.push_back(arg);
            continue;
        }
        std::ifstream in(arg.substr(1));
        if (!in) throw KioskConfigError(fmt::format("{}: cannot open the overrides file", arg.substr(1)));
        for (std::string line; std::getline(in, line);) {
            const auto first = line.find_first_not_of(" \t");
            if (first == std::string::npos || line[first] == '#') continue;
            out.push_back(line.substr(first));
        }
    }
    return out;
}

}  // namespace mogao
