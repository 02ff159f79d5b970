// SPDX-License-Identifier: Apache-2.0
#include "appliance/calibration/mpcdi_number.h"

#include <charconv>
#include <cmath>
#include <system_error>

namespace mogao {
namespace {

std::string_view trim(std::string_view s) {
    const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
    while (!s.empty() && space(s.front())) s.remove_prefix(1);
    while (!s.empty() && space(s.back())) s.remove_suffix(1);
    return s;
}

}  // namespace

std::string format_number(double value) {
    char buf[64];
    auto [end, ec] = std::to_chars(buf, buf + sizeof buf, value, std::chars_format::general, 6);
    if (ec == std::errc{}) {
        const std::optional<double> back = parse_number(std::string_view(buf, static_cast<std::size_t>(end - buf)));
        if (back && *back == value) return std::string(buf, end);
    }
    auto [end2, ec2] = std::to_chars(buf, buf + sizeof buf, value);
    return ec2 == std::errc{} ? std::string(buf, end2) : std::string("nan");
}

double round_to_g(double value) {
    char buf[64];
    const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, value, std::chars_format::general, 6);
    if (ec != std::errc{}) return value;
    return parse_number(std::string_view(buf, static_cast<std::size_t>(end - buf))).value_or(value);
}

std::optional<double> parse_number(std::string_view text) {
    const std::string_view s = trim(text);
    if (s.empty()) return std::nullopt;
    // from_chars rejects a leading '+'; XML writers never emit one but the text is legal decimal.
    const std::string_view body = s.front() == '+' ? s.substr(1) : s;
    double value = 0.0;
    const auto [end, ec] = std::from_chars(body.data(), body.data() + body.size(), value, std::chars_format::general);
    if (ec != std::errc{} || end != body.data() + body.size() || !std::isfinite(value)) return std::nullopt;
    return value;
}

std::optional<int> parse_int(std::string_view text) {
    const std::string_view s = trim(text);
    int value = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
    if (s.empty() || ec != std::errc{} || end != s.data() + s.size()) return std::nullopt;
    return value;
}

}  // namespace mogao
