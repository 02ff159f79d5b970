// SPDX-License-Identifier: Apache-2.0
// The PLY header's parser (ply_header.h).
#include "renderfarm/scene/ply_header.h"

#include <charconv>

#include <fmt/format.h>

#include "renderfarm/scene/mesh_io.h"

namespace mogao::ply {

namespace {

struct TypeName {
    std::string_view name;
    Type type;
};
constexpr TypeName kTypeNames[] = {
    {"char", Type::i8},   {"int8", Type::i8},     {"uchar", Type::u8},   {"uint8", Type::u8},
    {"short", Type::i16}, {"int16", Type::i16},   {"ushort", Type::u16}, {"uint16", Type::u16},
    {"int", Type::i32},   {"int32", Type::i32},   {"uint", Type::u32},   {"uint32", Type::u32},
    {"float", Type::f32}, {"float32", Type::f32}, {"double", Type::f64}, {"float64", Type::f64},
};

}  // namespace

std::optional<Type> parse_type(std::string_view s) {
    for (const TypeName& t : kTypeNames) {
        if (t.name == s) return t.type;
    }
    return std::nullopt;
}

std::size_t size_of(Type t) {
    switch (t) {
        case Type::i8:
        case Type::u8:
            return 1;
        case Type::i16:
        case Type::u16:
            return 2;
        case Type::i32:
        case Type::u32:
        case Type::f32:
            return 4;
        case Type::f64:
            return 8;
    }
    return 0;
}

bool is_integer(Type t) { return t != Type::f32 && t != Type::f64; }

namespace {

constexpr std::size_t kMaxHeaderBytes = std::size_t{1} << 20;

std::vector<std::string_view> split_words(std::string_view line) {
    std::vector<std::string_view> words;
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
        const std::size_t start = i;
        while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
        if (i > start) words.push_back(line.substr(start, i - start));
    }
    return words;
}

}  // namespace

Header parse_header(std::string_view bytes, const std::string& file) {
    Header h;
    std::size_t pos = 0;
    std::size_t line_no = 0;
    auto next_line = [&](std::string_view& out) {
        if (pos >= bytes.size() || pos > kMaxHeaderBytes) return false;
        const std::size_t nl = bytes.find('\n', pos);
        const std::size_t end = nl == std::string_view::npos ? bytes.size() : nl;
        out = bytes.substr(pos, end - pos);
        pos = nl == std::string_view::npos ? bytes.size() : nl + 1;
        if (!out.empty() && out.back() == '\r') out.remove_suffix(1);
        ++line_no;
        return true;
    };
    auto fail = [&](const std::string& why) {
        return MeshLoadError(file, fmt::format("header line {}: {}", line_no, why));
    };

    std::string_view line;
    if (!next_line(line) || line != "ply") throw MeshLoadError(file, "not a PLY file (first line is not 'ply')");
    bool have_format = false;
    for (;;) {
        if (!next_line(line)) throw MeshLoadError(file, "PLY header has no end_header line (truncated or not PLY)");
        const auto w = split_words(line);
        if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
        if (w[0] == "end_header") break;
        if (w[0] == "format") {
            if (w.size() != 3) throw fail("malformed format line");
            if (w[1] == "ascii") h.format = Format::ascii;
            else if (w[1] == "binary_little_endian") h.format = Format::binary_le;
            else if (w[1] == "binary_big_endian") h.format = Format::binary_be;
            else throw fail(fmt::format("unsupported format '{}'", w[1]));
            if (w[2] != "1.0" && w[2] != "1") throw fail(fmt::format("unsupported format version '{}'", w[2]));
            have_format = true;
        } else if (w[0] == "element") {
            std::uint64_t count = 0;
            if (w.size() != 3) throw fail("malformed element line");
            const auto r = std::from_chars(w[2].data(), w[2].data() + w[2].size(), count);
            if (r.ec != std::errc{} || r.ptr != w[2].data() + w[2].size()) {
                throw fail(fmt::format("bad count '{}' for element '{}'", w[2], w[1]));
            }
            h.elements.push_back(Element{std::string(w[1]), count, {}});
        } else if (w[0] == "property") {
            if (h.elements.empty()) throw fail("property before any element");
            Property p;
            const bool list = w.size() >= 2 && w[1] == "list";
            if ((list && w.size() != 5) || (!list && w.size() != 3)) throw fail("malformed property line");
            p.name = std::string(w.back());
            p.is_list = list;
            const auto type = parse_type(list ? w[3] : w[1]);
            if (!type)
                throw fail(fmt::format("unknown property type '{}' for property '{}'", list ? w[3] : w[1], p.name));
            p.type = *type;
            if (list) {
                const auto ct = parse_type(w[2]);
                if (!ct || !is_integer(*ct))
                    throw fail(
                        fmt::format("unknown or non-integer list count type '{}' for property '{}'", w[2], p.name));
                p.count_type = *ct;
            }
            h.elements.back().props.push_back(std::move(p));
        } else {
            throw fail(fmt::format("unknown header keyword '{}'", w[0]));
        }
    }
    if (!have_format) throw MeshLoadError(file, "PLY header has no format line");
    h.body_offset = pos;
    h.body_line = line_no + 1;
    return h;
}

}  // namespace mogao::ply
