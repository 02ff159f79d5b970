// SPDX-License-Identifier: Apache-2.0
// Number text of mpcdi.xml, locale-independent (std::to_chars / std::from_chars).
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace mogao {

// The reference library prints with printf "%g" (6 significant digits: 0.555556, 2.2, 1). This
// prints "%g" whenever that text reads back as exactly `value`, so the fixtures' numbers are
// written byte for byte; otherwise the shortest text that reads back exactly (e.g.
// 0.55555555555555558), so write -> read never changes a value.
[[nodiscard]] std::string format_number(double value);

// The value "%g" prints, read back: 6 significant digits (0.3700086728 -> 0.370009).
[[nodiscard]] double round_to_g(double value);

// A finite decimal number, the whole text (surrounding XML whitespace trimmed): no trailing junk,
// no NaN/inf, no hex. nullopt otherwise.
[[nodiscard]] std::optional<double> parse_number(std::string_view text);

// A decimal integer, the whole text (whitespace trimmed), in [INT32_MIN, INT32_MAX].
[[nodiscard]] std::optional<int> parse_int(std::string_view text);

}  // namespace mogao
