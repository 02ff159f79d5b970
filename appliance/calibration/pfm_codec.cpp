// SPDX-License-Identifier: Apache-2.0
#include "appliance/calibration/pfm_codec.h"

#include <bit>
#include <cmath>
#include <cstring>
#include <string_view>

#include "appliance/calibration/mpcdi_error.h"
#include "appliance/calibration/mpcdi_number.h"

namespace mogao {
namespace {

bool is_space(std::uint8_t c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

float load_float(const std::uint8_t* p, bool little_endian) {
    std::uint32_t bits = 0;
    if (little_endian) {
        bits = std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 | std::uint32_t{p[3]} << 24;
    } else {
        bits = std::uint32_t{p[3]} | std::uint32_t{p[2]} << 8 | std::uint32_t{p[1]} << 16 | std::uint32_t{p[0]} << 24;
    }
    return std::bit_cast<float>(bits);
}

void store_float_le(std::uint8_t* p, float value) {
    const auto bits = std::bit_cast<std::uint32_t>(value);
    p[0] = static_cast<std::uint8_t>(bits);
    p[1] = static_cast<std::uint8_t>(bits >> 8);
    p[2] = static_cast<std::uint8_t>(bits >> 16);
    p[3] = static_cast<std::uint8_t>(bits >> 24);
}

std::string size_text(ImageSize s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

}  // namespace

PfmMap decode_pfm(std::span<const std::uint8_t> bytes, const std::string& who) {
    const auto fail = [&](const std::string& why) { return MpcdiError(who + ": PFM " + why); };
    if (bytes.size() < 2 || bytes[0] != 'P' || (bytes[1] != 'F' && bytes[1] != 'f')) {
        throw fail("magic is not 'PF' or 'Pf'");
    }
    PfmMap map;
    map.channels = bytes[1] == 'F' ? 3 : 1;
    std::size_t pos = 2;
    // Header tokens; the whitespace before each is one or more bytes.
    const auto token = [&](const char* field) -> std::string_view {
        const std::size_t before = pos;
        while (pos < bytes.size() && is_space(bytes[pos])) ++pos;
        if (pos == before) throw fail(std::string("header: no whitespace before the ") + field);
        const std::size_t start = pos;
        while (pos < bytes.size() && !is_space(bytes[pos]) && pos - start < 64) ++pos;
        if (pos == start) throw fail(std::string("header: missing ") + field);
        return {reinterpret_cast<const char*>(bytes.data()) + start, pos - start};
    };
    const std::string_view w_text = token("width");
    const std::string_view h_text = token("height");
    const std::string_view scale_text = token("scale");
    const std::optional<int> width = parse_int(w_text);
    const std::optional<int> height = parse_int(h_text);
    if (!width || !height || *width < 1 || *height < 1 || *width > kMaxMapDimension || *height > kMaxMapDimension) {
        throw fail("header: size '" + std::string(w_text) + " " + std::string(h_text) + "' is outside 1.." +
                   std::to_string(kMaxMapDimension) + " per side");
    }
    const std::optional<double> scale = parse_number(scale_text);
    if (!scale || *scale == 0.0) {
        throw fail("header: scale '" + std::string(scale_text) +
                   "' is not a non-zero number (its sign gives the byte order)");
    }
    if (pos >= bytes.size() || !is_space(bytes[pos]))
        throw fail("header: scale is not followed by one whitespace byte");
    ++pos;
    map.size = {*width, *height};
    const std::size_t count = static_cast<std::size_t>(map.size.pixel_count()) * static_cast<std::size_t>(map.channels);
    const std::size_t data = bytes.size() - pos;
    if (data != count * 4) {
        throw fail("size mismatch: " + std::to_string(data) + " data bytes after the header, " + size_text(map.size) +
                   " x " + std::to_string(map.channels) + " channels x 4 = " + std::to_string(count * 4) +
                   " expected (" + (data < count * 4 ? "truncated" : "trailing bytes") + ")");
    }
    const bool little = *scale < 0.0;
    map.values.resize(count);
    const std::size_t row_values = static_cast<std::size_t>(map.size.width) * static_cast<std::size_t>(map.channels);
    for (int stored = 0; stored < map.size.height; ++stored) {
        const int y = map.size.height - 1 - stored;  // first stored row is the bottom row
        const std::uint8_t* src = bytes.data() + pos + static_cast<std::size_t>(stored) * row_values * 4;
        float* dst = map.values.data() + static_cast<std::size_t>(y) * row_values;
        for (std::size_t i = 0; i < row_values; ++i) {
            const float value = load_float(src + 4 * i, little);
            if (std::isinf(value)) {
                throw fail("sample at (" + std::to_string(i / static_cast<std::size_t>(map.channels)) + ", " +
                           std::to_string(y) + ") channel " +
                           std::to_string(i % static_cast<std::size_t>(map.channels)) +
                           " is infinite (only finite values or NaN are accepted)");
            }
            dst[i] = value;
        }
    }
    return map;
}

std::vector<std::uint8_t> encode_pfm(const PfmMap& map, const std::string& who) {
    if (map.channels != 1 && map.channels != 3) {
        throw MpcdiError(who + ": PFM channels " + std::to_string(map.channels) + " must be 1 or 3");
    }
    if (map.size.width < 1 || map.size.height < 1 || map.size.width > kMaxMapDimension ||
        map.size.height > kMaxMapDimension) {
        throw MpcdiError(who + ": PFM size " + size_text(map.size) + " is outside 1.." +
                         std::to_string(kMaxMapDimension));
    }
    const std::size_t row_values = static_cast<std::size_t>(map.size.width) * static_cast<std::size_t>(map.channels);
    if (map.values.size() != row_values * static_cast<std::size_t>(map.size.height)) {
        throw MpcdiError(who + ": PFM holds " + std::to_string(map.values.size()) + " values, " + size_text(map.size) +
                         " x " + std::to_string(map.channels) + " expected");
    }
    for (std::size_t i = 0; i < map.values.size(); ++i) {
        if (std::isinf(map.values[i])) throw MpcdiError(who + ": PFM value " + std::to_string(i) + " is infinite");
    }
    const std::string header = std::string(map.channels == 3 ? "PF" : "Pf") + "\n" + std::to_string(map.size.width) +
                               " " + std::to_string(map.size.height) + "\n-1.000000\n";
    std::vector<std::uint8_t> bytes(header.size() + map.values.size() * 4);
    std::memcpy(bytes.data(), header.data(), header.size());
    std::uint8_t* out = bytes.data() + header.size();
    for (int stored = 0; stored < map.size.height; ++stored) {
        const float* src = map.values.data() + static_cast<std::size_t>(map.size.height - 1 - stored) * row_values;
        for (std::size_t i = 0; i < row_values; ++i, out += 4) store_float_le(out, src[i]);
    }
    return bytes;
}

}  // namespace mogao
