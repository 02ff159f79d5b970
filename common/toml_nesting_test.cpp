// SPDX-License-Identifier: Apache-2.0
#include "common/toml_nesting.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace mogao {
namespace {

std::string nested_arrays(int levels) { return "a = " + std::string(levels, '[') + std::string(levels, ']') + "\n"; }

TEST(TomlNesting, ArraysDeeperThanTheLimitAreFoundOnTheirLine) {
    const auto at_limit = toml_nesting_excess("x = 1\n" + nested_arrays(kMaxTomlNesting));
    EXPECT_FALSE(at_limit.has_value());
    const auto over = toml_nesting_excess("x = 1\n# comment\n" + nested_arrays(kMaxTomlNesting + 1));
    ASSERT_TRUE(over.has_value());
    EXPECT_EQ(over->line, 3u);
    EXPECT_EQ(over->max_depth, kMaxTomlNesting);
}

TEST(TomlNesting, InlineTablesAndArraysCountTogether) {
    std::string text = "a = ";
    for (int i = 0; i < 3; ++i) text += "{ b = [";
    text += "1";
    for (int i = 0; i < 3; ++i) text += "] }";
    EXPECT_FALSE(toml_nesting_excess(text, 6).has_value());
    EXPECT_TRUE(toml_nesting_excess(text, 5).has_value());
}

TEST(TomlNesting, BracketsInStringsAndCommentsAreNotLevels) {
    const std::string deep(100, '[');
    const std::string text = "a = \"" + deep + "\\\"" + deep + "\"\n" +                 // basic string, escaped quote
                             "b = '" + deep + "'\n" +                                   // literal string
                             "c = \"\"\"\n" + deep + "\n\"\" " + deep + "\n\"\"\"\n" +  // multi-line basic
                             "d = '''" + deep + "\n'' " + deep + "'''\n" +              // multi-line literal
                             "# " + deep + "\n" +                                       // comment
                             "[table]\n[[array]]\n" +                                   // headers close
                             "e = [[1], ['[']]\n";
    EXPECT_FALSE(toml_nesting_excess(text, 2).has_value());
    // The same counting still sees real levels after all of that, on the right line.
    const auto over = toml_nesting_excess(text + "f = [[[1]]]\n", 2);
    ASSERT_TRUE(over.has_value());
    EXPECT_EQ(over->line, 13u);
}

TEST(TomlNesting, DottedKeysAreLevelsToo) {
    const auto dotted = [](int segments) {
        std::string key = "a";
        for (int i = 1; i < segments; ++i) key += ".a";
        return key;
    };
    EXPECT_FALSE(toml_nesting_excess(dotted(kMaxTomlNesting + 1) + " = 1\n").has_value());
    EXPECT_TRUE(toml_nesting_excess(dotted(kMaxTomlNesting + 2) + " = 1\n").has_value());
    // A header's brackets and dots, dots with blanks and quoted segments count; dots inside quotes
    // do not. "[a.a.a]" is 1 + 2 levels, "a . "b.c.d.e" . 'f'" 2.
    EXPECT_TRUE(toml_nesting_excess("[" + dotted(3) + "]\n", 2).has_value());
    EXPECT_FALSE(toml_nesting_excess("[" + dotted(3) + "]\n", 3).has_value());
    EXPECT_TRUE(toml_nesting_excess("a . \"b.c.d.e\" . 'f' = 1\n", 1).has_value());
    EXPECT_FALSE(toml_nesting_excess("a . \"b.c.d.e\" . 'f' = 1\n", 2).has_value());
    // Within brackets the two add up; '=' and ',' end a run, so numbers and keys do not pile up.
    EXPECT_TRUE(toml_nesting_excess("x = {a.b = 1}\n", 1).has_value());
    EXPECT_FALSE(toml_nesting_excess("x = {a.b = 1}\n", 2).has_value());
    EXPECT_FALSE(toml_nesting_excess("x.y = [1.5, 2.5, 3.5]\nz = 1979-05-27T07:32:00.999\n", 2).has_value());
    const auto over = toml_nesting_excess("x = 1\n" + dotted(100000) + " = 1\n");
    ASSERT_TRUE(over.has_value());
    EXPECT_EQ(over->line, 2u);
}

TEST(TomlNesting, UnterminatedStringsAndStrayClosersEndQuietly) {
    EXPECT_FALSE(toml_nesting_excess("a = \"[[[[[[", 2).has_value());
    EXPECT_FALSE(toml_nesting_excess("a = ''']]]]]][[", 2).has_value());
    EXPECT_FALSE(toml_nesting_excess("]]]]]] a = [[1]]", 2).has_value());
    EXPECT_TRUE(toml_nesting_excess("]]]]]] a = [[[1]]]", 2).has_value());
}

TEST(TomlUtf8, WellFormedTextPasses) {
    EXPECT_FALSE(toml_invalid_utf8("").has_value());
    EXPECT_FALSE(toml_invalid_utf8("a = 'plain'\n").has_value());
    // 2, 3 and 4 bytes, the edges of table 3-7: U+0080, U+07FF, U+0800, U+D7FF, U+E000, U+FFFF,
    // U+10000, U+10FFFF; and NUL.
    EXPECT_FALSE(toml_invalid_utf8("a = '\xC2\x80 \xDF\xBF \xE0\xA0\x80 \xED\x9F\xBF \xEE\x80\x80 "
                                   "\xEF\xBF\xBF \xF0\x90\x80\x80 \xF4\x8F\xBF\xBF'\n")
                     .has_value());
    EXPECT_FALSE(toml_invalid_utf8(std::string_view("a\0b", 3)).has_value());
}

TEST(TomlUtf8, EveryIllFormedSequenceIsFoundOnItsLineAndColumn) {
    const char* bad[] = {
        "\x80",              // a continuation byte alone
        "\xC0\xAF",          // overlong '/'
        "\xC1\xBF",          // overlong
        "\xE0\x80\x80",      // overlong 3-byte
        "\xED\xA0\x80",      // a surrogate, U+D800
        "\xF0\x80\x80\x80",  // overlong 4-byte
        "\xF4\x90\x80\x80",  // above U+10FFFF
        "\xF5\x80\x80\x80",  // no such lead byte
        "\xFF",
        "\xE2\x82",   // cut short at the end of the text
        "\xE2\x82x",  // cut short by an ASCII byte
    };
    for (const char* seq : bad) {
        const std::string text = "a = 1\n# \xC3\xA9\nb = '" + std::string(seq);
        const auto found = toml_invalid_utf8(text);
        ASSERT_TRUE(found.has_value()) << seq;
        EXPECT_EQ(found->line, 3U) << seq;
        EXPECT_EQ(found->column, 6U) << seq;
    }
}

TEST(TomlNesting, ALimitBelowOneIsRefused) {
    EXPECT_THROW((void)toml_nesting_excess("a = 1", 0), std::invalid_argument);
}

}  // namespace
}  // namespace mogao
