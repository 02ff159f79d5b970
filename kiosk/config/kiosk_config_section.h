// SPDX-License-Identifier: Apache-2.0
// The kiosk configuration parser's view of one TOML table (internal to kiosk/config/): typed reads
// that check a value and throw KioskConfigError naming the file, the line (when toml11 knows it),
// the field as "[table].key", the value and the limit.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <toml.hpp>

#include "kiosk/config/kiosk_config.h"
#include "kiosk/config/kiosk_config_schema.h"

namespace mogao::kiosk_config {

using Value = toml::value;

// The file's text (at most 1 MiB). Throws KioskConfigError naming the file.
[[nodiscard]] std::string read_config_text(const std::filesystem::path& file);

// "an integer", "a string", ... for messages.
[[nodiscard]] std::string type_name(const Value& v);

// Where messages point: the file, and the line of the offending value when toml11 knows it.
struct Context {
    std::string file;
    std::filesystem::path dir;  // relative paths are resolved against it

    [[noreturn]] void fail(const Value* where, const std::string& message) const;
    [[nodiscard]] std::filesystem::path resolve(const std::string& text) const;
};

// The file's context: its name for messages, its folder for relative paths.
[[nodiscard]] Context context_of(const std::filesystem::path& name);
// `text` parsed as TOML, refusing what toml11 would crash on. Throws KioskConfigError.
[[nodiscard]] Value parse_toml(std::string_view text, const Context& ctx);

// One [table]: typed reads that check ranges, and a final check for unknown keys (the schema's keys
// of the table are the known ones).
class Section {
public:
    Section(const Context& ctx, std::string name, const Value* table);

    [[nodiscard]] const std::string& name() const { return name_; }
    [[nodiscard]] std::string field(std::string_view key) const;
    [[nodiscard]] const Value* find(std::string_view key) const;
    [[noreturn]] void fail(const Value* where, std::string_view key, const std::string& what) const;

    [[nodiscard]] std::string as_string(const Value& v, std::string_view key) const;
    [[nodiscard]] bool as_boolean(const Value& v, std::string_view key) const;
    [[nodiscard]] int as_integer(const Value& v, std::string_view key, int lo, int hi) const;
    // An integer or a float that `limit` accepts; `range` writes the limit in messages.
    [[nodiscard]] double as_number(const Value& v, std::string_view key, const NumberLimit& limit,
                                   std::string_view range) const;
    // "WIDTHxHEIGHT", each side in [lo, 16384].
    [[nodiscard]] ImageSize as_size(const Value& v, std::string_view key, int lo) const;
    // A path to an existing regular file.
    [[nodiscard]] std::filesystem::path existing_file(const Value& v, std::string_view key) const;

    // Unknown keys are errors: a typo must not fall back to a default silently.
    void finish() const;

    [[nodiscard]] const Context& context() const { return ctx_; }

private:
    const Context& ctx_;
    std::string name_;
    const Value* table_;
    std::vector<std::string> known_;
};

// The top-level [name] of `root`; absent: an empty section.
[[nodiscard]] Section section(const Context& ctx, const Value& root, const std::string& name);
// The [parent.key] table inside `parent` (e.g. [navigation.detector]); absent: an empty section.
[[nodiscard]] Section subsection(const Section& parent, std::string_view key);

}  // namespace mogao::kiosk_config
