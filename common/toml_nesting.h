// SPDX-License-Identifier: Apache-2.0
// A guard run on TOML text before toml11 parses it: how deeply tables and arrays nest.
//
// Why: toml11 (3.7, Debian 12) parses nested arrays and inline tables by recursion, one set of
// stack frames per level, with no limit of its own. "a = [[[[...": about 10000 levels in a file
// of 20 kB overflow the stack (SIGSEGV), far fewer under ASan -- found by fuzzing the kiosk's
// configuration (tests/fuzz, kiosk_config). Dotted keys nest tables without brackets: toml11
// copies and destroys such tables recursively, and "a.a.a...= 1" with 100000 segments crashed it
// too (an inline table of 100000 did not end within a minute). A kiosk configuration or a rig file
// never needs more than a few levels, so every TOML reader checks the text first and refuses it,
// naming the line.
//
// The scan follows TOML 1.0's lexical rules (https://toml.io/en/v1.0.0) only as far as needed to
// count levels, outside comments ('#' to the end of the line) and outside the four kinds of
// string ("...", '...', """...""", '''...''', with the backslash escapes of basic strings):
// '[', '{' open a level and ']', '}' close one; each '.' of a dotted run (bare or quoted key
// segments, or a number, separated by dots and blanks) adds a level until the run ends. A level
// counts when the open brackets plus the current run's dots exceed the limit. A table header
// "[a.b]" counts as its brackets and dots, closed on its own line. Text that is not valid TOML is
// not judged here (toml11 does it, and stops at the first error): a single-line string ends at
// the end of its line, an unterminated multi-line string ends the scan.
//
// The second guard, toml_invalid_utf8: toml11 3.7 reads out of bounds (heap-buffer-overflow under
// ASan) when a literal string ('...' or '''...''') holds bytes that are not UTF-8: to point at the
// bad byte it rewinds a copy of the string with an iterator into the whole file (parser.hpp,
// parse_literal_string / parse_ml_literal_string) -- found by fuzzing the kiosk's configuration
// (regression input tests/fuzz/corpus/kiosk_config/regression-literal-string-invalid-utf8.toml).
// TOML 1.0 requires the whole document to be UTF-8, so every TOML reader refuses text that is
// not, naming the line, before toml11 sees it.
#pragma once

#include <cstddef>
#include <optional>
#include <string_view>

namespace mogao {

// Levels a TOML reader of this project accepts: far above any real file, far below what toml11's
// recursion survives (the worst text this limit lets through, 32 inline tables each under a
// 31-dot key, is parsed by toml11 in kiosk/config/kiosk_config_test.cpp, also under ASan).
inline constexpr int kMaxTomlNesting = 32;

struct TomlNestingExcess {
    std::size_t line = 0;  // 1-based line of the bracket or dot that opened level max_depth + 1
    int max_depth = 0;     // the limit that was passed
};

// The first place where `text` nests arrays / inline tables deeper than `max_depth` levels, or
// nullopt when it never does. Throws std::invalid_argument when max_depth < 1. Linear in the
// size of the text, no recursion, no allocation.
[[nodiscard]] std::optional<TomlNestingExcess> toml_nesting_excess(std::string_view text,
                                                                   int max_depth = kMaxTomlNesting);

struct TomlInvalidUtf8 {
    std::size_t line = 0;    // 1-based
    std::size_t column = 0;  // 1-based, in bytes
};

// The first byte of `text` that does not start a well-formed UTF-8 sequence -- Unicode 15.0,
// section 3.9, table 3-7 (no overlong forms, no surrogates, nothing above U+10FFFF; the same
// table as toml11's lex_utf8_code) -- or nullopt when all of it is UTF-8. NUL is a valid code
// point here (TOML forbids control characters; toml11 reports those). Linear, no allocation.
[[nodiscard]] std::optional<TomlInvalidUtf8> toml_invalid_utf8(std::string_view text);

}  // namespace mogao
