// SPDX-License-Identifier: Apache-2.0
#include "kiosk/config/kiosk_config_section.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include "common/request_limits.h"
#include "common/toml_nesting.h"

namespace mogao::kiosk_config {

namespace fs = std::filesystem;

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

void Context::fail(const Value* where, const std::string& message) const {
    if (where != nullptr) {
        const auto line = where->location().line();
        if (line > 0 && where->location().file_name() != "unknown file") {
            throw KioskConfigError(fmt::format("{}:{}: {}", file, line, message));
        }
    }
    throw KioskConfigError(fmt::format("{}: {}", file, message));
}

fs::path Context::resolve(const std::string& text) const {
    const fs::path p(text);
    return (p.is_relative() ? dir / p : p).lexically_normal();
}

Section::Section(const Context& ctx, std::string name, const Value* table)
    : ctx_(ctx), name_(std::move(name)), table_(table), known_(schema_keys(name_)) {}

std::string Section::field(std::string_view key) const { return fmt::format("[{}].{}", name_, key); }

const Value* Section::find(std::string_view key) const {
    if (table_ == nullptr) return nullptr;
    const auto& t = table_->as_table();
    const auto it = t.find(std::string(key));
    return it == t.end() ? nullptr : &it->second;
}

void Section::fail(const Value* where, std::string_view key, const std::string& what) const {
    ctx_.fail(where != nullptr ? where : table_, field(key) + what);
}

std::string Section::as_string(const Value& v, std::string_view key) const {
    if (!v.is_string()) fail(&v, key, ": expected a string, got " + type_name(v));
    return v.as_string().str;
}

bool Section::as_boolean(const Value& v, std::string_view key) const {
    if (!v.is_boolean()) fail(&v, key, ": expected true or false, got " + type_name(v));
    return v.as_boolean();
}

int Section::as_integer(const Value& v, std::string_view key, int lo, int hi) const {
    if (!v.is_integer()) fail(&v, key, ": expected an integer, got " + type_name(v));
    const std::int64_t n = v.as_integer();
    if (n < lo || n > hi) fail(&v, key, fmt::format(" = {} is outside [{}, {}]", n, lo, hi));
    return static_cast<int>(n);
}

double Section::as_number(const Value& v, std::string_view key, const NumberLimit& limit,
                          std::string_view range) const {
    double x = 0;
    if (v.is_integer()) {
        x = static_cast<double>(v.as_integer());
    } else if (v.is_floating()) {
        x = v.as_floating();
    } else {
        fail(&v, key, ": expected a number, got " + type_name(v));
    }
    if (!std::isfinite(x) || !limit.accepts(x)) fail(&v, key, fmt::format(" = {} is outside {}", x, range));
    return x;
}

ImageSize Section::as_size(const Value& v, std::string_view key, int lo) const {
    constexpr int kMaxSide = request_limits::kImageSide.max;
    const std::string text = as_string(v, key);
    ImageSize s;
    if (!parse_size(text, s)) fail(&v, key, fmt::format(": '{}' is not WIDTHxHEIGHT (e.g. \"1920x1080\")", text));
    if (s.width < lo || s.width > kMaxSide || s.height < lo || s.height > kMaxSide) {
        fail(&v, key, fmt::format(" = '{}' is outside [{}, {}] pixels per side", text, lo, kMaxSide));
    }
    return s;
}

fs::path Section::existing_file(const Value& v, std::string_view key) const {
    const std::string text = as_string(v, key);
    if (text.empty()) fail(&v, key, ": empty path");
    const fs::path p = ctx_.resolve(text);
    std::error_code ec;
    if (!fs::exists(p, ec)) fail(&v, key, fmt::format(": '{}' does not exist", p.string()));
    if (!fs::is_regular_file(p, ec)) fail(&v, key, fmt::format(": '{}' is not a regular file", p.string()));
    return p;
}

void Section::finish() const {
    if (table_ == nullptr) return;
    std::set<std::string> unknown;
    for (const auto& [key, value] : table_->as_table()) {
        if (std::find(known_.begin(), known_.end(), key) == known_.end()) unknown.insert(key);
    }
    if (unknown.empty()) return;
    const std::string& key = *unknown.begin();
    fail(&table_->as_table().at(key), key, fmt::format(": unknown field (known: {})", fmt::join(known_, ", ")));
}

Section section(const Context& ctx, const Value& root, const std::string& name) {
    const auto& t = root.as_table();
    const auto it = t.find(name);
    if (it == t.end()) return Section(ctx, name, nullptr);
    if (!it->second.is_table())
        ctx.fail(&it->second, fmt::format("[{}]: expected a table, got {}", name, type_name(it->second)));
    return Section(ctx, name, &it->second);
}

Section subsection(const Section& parent, std::string_view key) {
    const std::string name = fmt::format("{}.{}", parent.name(), key);
    const Value* v = parent.find(key);
    if (v != nullptr && !v->is_table())
        parent.fail(v, key, ": expected a table ([" + name + "]), got " + type_name(*v));
    return Section(parent.context(), name, v);
}

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

Context context_of(const std::filesystem::path& name) {
    return {name.string(), name.has_parent_path() ? name.parent_path() : fs::path(".")};
}

}  // namespace mogao::kiosk_config
