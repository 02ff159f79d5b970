// SPDX-License-Identifier: Apache-2.0
// The schema table against what is written elsewhere: kiosk.example.toml shows every key of the table
// and no other, with the table's default; the parser refuses each plain number just outside its limit
// with the table's range in the message; docs/kiosk.md's reference block is the table's.
#include "kiosk/config/kiosk_config_schema.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <toml.hpp>

#include "kiosk/config/config_overrides.h"
#include "kiosk/config/kiosk_config_test_support.h"

namespace mogao {
namespace {

using kiosk_config_test::KioskConfigTest;

struct ExampleKey {
    std::string value;  // as written after "key = "
    int line = 0;
};

// "table.key" -> the first line of the example that writes the key, commented out or not, as TOML
// ("# key = value  # comment" counts; prose that happens to contain " = " does not parse and is skipped).
std::map<std::string, ExampleKey> example_keys() {
    const std::regex header(R"(^(# )?\[([a-z_.]+)\].*)");
    const std::regex key_line(R"(^(# )?([a-z_0-9]+) = (.*)$)");
    std::map<std::string, ExampleKey> keys;
    std::istringstream lines{std::string(kiosk_example_toml())};
    std::string table;
    int number = 0;
    for (std::string line; std::getline(lines, line);) {
        ++number;
        std::smatch m;
        if (std::regex_match(line, m, header)) {
            table = m[2];
            // "[navigation.detector]" shows the key "detector" of [navigation]
            if (table.find('.') != std::string::npos) keys.try_emplace(table, ExampleKey{"{}", number});
            continue;
        }
        if (!std::regex_match(line, m, key_line) || table.empty()) continue;
        try {
            std::istringstream one("k = " + m[3].str());
            (void)toml::parse(one, "line");
        } catch (const std::exception&) {
            continue;
        }
        keys.try_emplace(table + "." + m[2].str(), ExampleKey{m[3].str(), number});
    }
    return keys;
}

toml::value toml_of(const std::string& value) {
    std::istringstream one("k = " + value);
    return toml::find(toml::parse(one, "value"), "k");
}

TEST(KioskConfigSchema, TheExampleShowsEveryKeyOfTheSchemaAndNoOther) {
    const auto example = example_keys();
    std::set<std::string> schema;
    for (const ConfigKey& row : kiosk_config_schema()) {
        const std::string name = fmt::format("{}.{}", row.table, row.key);
        schema.insert(name);
        EXPECT_EQ(example.count(name), 1u) << name << " is in the schema but kiosk.example.toml does not show it";
    }
    for (const auto& [name, key] : example) {
        EXPECT_EQ(schema.count(name), 1u)
            << "kiosk.example.toml:" << key.line << " shows " << name << ", which the schema does not have";
    }
    EXPECT_GT(schema.size(), 100u);
}

// Site values (paths, files, the farm) are examples; every other key shows its default.
TEST(KioskConfigSchema, TheExampleShowsTheSchemasDefaults) {
    const auto example = example_keys();
    std::set<std::string> seen;
    int compared = 0;
    for (const ConfigKey& row : kiosk_config_schema()) {
        const std::string name = fmt::format("{}.{}", row.table, row.key);
        if (!seen.insert(name).second) continue;  // a key's first row (camera_fps: the replay's rate)
        const bool site_value = row.type == KeyType::path || row.type == KeyType::file || row.type == KeyType::table;
        if (!row.default_text.empty() || !row.required.empty() || site_value ||
            std::holds_alternative<std::monostate>(row.member))
            continue;
        const auto it = example.find(name);
        if (it == example.end()) continue;  // the test above fails
        const toml::value shown = toml_of(it->second.value);
        const toml::value expected = toml_of(schema_default(row));
        const bool numbers =
            (shown.is_integer() || shown.is_floating()) && (expected.is_integer() || expected.is_floating());
        if (numbers) {
            const auto as_double = [](const toml::value& v) {
                return v.is_integer() ? static_cast<double>(v.as_integer()) : v.as_floating();
            };
            EXPECT_DOUBLE_EQ(as_double(shown), as_double(expected))
                << "kiosk.example.toml:" << it->second.line << ": " << name << " shows " << it->second.value
                << ", the default is " << schema_default(row);
        } else {
            EXPECT_EQ(shown, expected) << "kiosk.example.toml:" << it->second.line << ": " << name << " shows "
                                       << it->second.value << ", the default is " << schema_default(row);
        }
        ++compared;
    }
    EXPECT_GT(compared, 80);
}

TEST(KioskConfigSchema, EachKeysRowsAreTogetherAndTablesInTheFilesOrder) {
    std::set<std::string> done;
    std::string previous;
    const auto sections = schema_sections();
    for (const ConfigKey& row : kiosk_config_schema()) {
        const std::string name = fmt::format("{}.{}", row.table, row.key);
        if (name != previous) {
            EXPECT_TRUE(done.insert(name).second) << name << "'s rows are not adjacent";
        }
        previous = name;
        const std::string top(row.table.substr(0, row.table.find('.')));
        EXPECT_NE(std::find(sections.begin(), sections.end(), top), sections.end()) << name;
        EXPECT_FALSE(row.doc.empty()) << name << " has no description";
    }
}

TEST(KioskConfigSchema, TheReferenceHasALinePerRow) {
    const std::string reference = config_reference_markdown();
    const auto rows = kiosk_config_schema();
    EXPECT_EQ(static_cast<std::size_t>(std::count(reference.begin(), reference.end(), '\n')), rows.size() + 2);
    EXPECT_NE(reference.find("| `[display] rate_hz` | number | `30` | [0.5, 240] Hz |"), std::string::npos)
        << reference;
    EXPECT_NE(reference.find("| `[quality] spp` | integer | `1` | [1, 4096] |"), std::string::npos) << reference;
}

// The parser checks each plain number against its row: one just above the limit is refused, and the
// message writes the row's range (the rows that apply to kGood's modes: headless, ideal, path).
TEST_F(KioskConfigTest, EveryPlainNumberIsRefusedJustAboveItsLimitWithTheSchemasRange) {
    int checked = 0;
    for (const ConfigKey& row : kiosk_config_schema()) {
        const bool plain = row.type == KeyType::integer || row.type == KeyType::number;
        const bool applies = row.when == When::always || row.when == When::headless || row.when == When::ideal ||
                             row.when == When::path_source;
        if (!plain || !applies || row.table.find('.') != std::string_view::npos) continue;
        const double above = row.limit.hi_open ? row.limit.hi : row.limit.hi + 1;
        const std::string value = fmt::format("{}", above);
        const std::string range =
            row.type == KeyType::integer ? fmt::format("[{}, {}]", row.limit.lo, row.limit.hi) : std::string(row.range);
        const std::string message = error_of(good({fmt::format("{}.{}={}", row.table, row.key, value)}));
        EXPECT_NE(message.find(fmt::format("[{}].{} = {} is outside {}", row.table, row.key, value, range)),
                  std::string::npos)
            << message;
        ++checked;
    }
    EXPECT_GE(checked, 20);
}

}  // namespace
}  // namespace mogao
