// SPDX-License-Identifier: Apache-2.0
#include "common/toml_nesting.h"

#include <stdexcept>
#include <string>

namespace mogao {
namespace {

// The position just past the string that starts at `i` (at a quote), or text.size() when it is
// not terminated. `line` counts the newlines inside (multi-line strings).
std::size_t skip_string(std::string_view text, std::size_t i, std::size_t& line) {
    const char quote = text[i];
    const bool basic = quote == '"';
    const bool multi = text.substr(i, 3) == std::string_view(basic ? "\"\"\"" : "'''");
    std::size_t j = i + (multi ? 3 : 1);
    while (j < text.size()) {
        const char c = text[j];
        if (basic && c == '\\') {
            if (j + 1 < text.size() && text[j + 1] == '\n') ++line;
            j += 2;
            continue;
        }
        if (c == '\n') {
            if (!multi) return j;  // a single-line string ends at the line's end (invalid TOML)
            ++line;
        }
        if (c == quote && (!multi || text.substr(j, 3) == std::string_view(basic ? "\"\"\"" : "'''"))) {
            // A multi-line string may end with up to two more quotes of its own ("""a""""").
            j += multi ? 3 : 1;
            for (int extra = 0; multi && extra < 2 && j < text.size() && text[j] == quote; ++extra) ++j;
            return j;
        }
        ++j;
    }
    return text.size();
}

}  // namespace

std::optional<TomlNestingExcess> toml_nesting_excess(std::string_view text, int max_depth) {
    if (max_depth < 1) {
        throw std::invalid_argument("toml_nesting_excess: max_depth must be >= 1, not " + std::to_string(max_depth));
    }
    int depth = 0;
    int dots = 0;  // dots of the dotted key (or number) being read: each is one more table level
    std::size_t line = 1;
    std::size_t i = 0;
    while (i < text.size()) {
        const char c = text[i];
        const bool in_dotted_run = c == '.' || c == ' ' || c == '\t' || c == '_' || c == '-' || c == '+' ||
                                   (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z');
        if (!in_dotted_run && c != '"' && c != '\'') dots = 0;
        switch (c) {
            case '\n':
                ++line;
                break;
            case '.':
                if (depth + ++dots > max_depth) return TomlNestingExcess{line, max_depth};
                break;
            case '#':
                while (i < text.size() && text[i] != '\n') ++i;
                continue;  // the newline is counted on the next turn
            case '"':
            case '\'':
                i = skip_string(text, i, line);
                continue;
            case '[':
            case '{':
                if (++depth + dots > max_depth) return TomlNestingExcess{line, max_depth};
                break;
            case ']':
            case '}':
                if (depth > 0) --depth;  // unbalanced closers are toml11's to report
                break;
            default:
                break;
        }
        ++i;
    }
    return std::nullopt;
}

namespace {

// Length of the well-formed UTF-8 sequence at text[i] (table 3-7), 0 when there is none.
std::size_t utf8_sequence_length(std::string_view text, std::size_t i) {
    const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
    const unsigned char b0 = byte(i);
    if (b0 <= 0x7F) return 1;
    // (sequence length, the second byte's range) by the first byte; later bytes are 80..BF.
    struct Lead {
        std::size_t n;
        unsigned char lo;
        unsigned char hi;
    };
    Lead lead{0, 0x80, 0xBF};
    if (b0 >= 0xC2 && b0 <= 0xDF) lead = {2, 0x80, 0xBF};
    else if (b0 == 0xE0) lead = {3, 0xA0, 0xBF};  // no overlong forms
    else if ((b0 >= 0xE1 && b0 <= 0xEC) || b0 == 0xEE || b0 == 0xEF) lead = {3, 0x80, 0xBF};
    else if (b0 == 0xED) lead = {3, 0x80, 0x9F};  // no surrogates
    else if (b0 == 0xF0) lead = {4, 0x90, 0xBF};
    else if (b0 >= 0xF1 && b0 <= 0xF3) lead = {4, 0x80, 0xBF};
    else if (b0 == 0xF4) lead = {4, 0x80, 0x8F};  // nothing above U+10FFFF
    else return 0;
    const auto [n, lo, hi] = lead;
    if (i + n > text.size()) return 0;
    if (byte(i + 1) < lo || byte(i + 1) > hi) return 0;
    for (std::size_t k = 2; k < n; ++k) {
        if (byte(i + k) < 0x80 || byte(i + k) > 0xBF) return 0;
    }
    return n;
}

}  // namespace

std::optional<TomlInvalidUtf8> toml_invalid_utf8(std::string_view text) {
    std::size_t line = 1;
    std::size_t line_start = 0;
    for (std::size_t i = 0; i < text.size();) {
        const std::size_t n = utf8_sequence_length(text, i);
        if (n == 0) return TomlInvalidUtf8{line, i - line_start + 1};
        if (text[i] == '\n') {
            ++line;
            line_start = i + 1;
        }
        i += n;
    }
    return std::nullopt;
}

}  // namespace mogao
