// SPDX-License-Identifier: Apache-2.0
// Internal to the PLY reader (ply_reader.cpp): the PLY header's model and parser. Format: Greg Turk, "The PLY
// Polygon File Format" (1994), as Paul Bourke's page gives it; types by either name (char/int8, ..., double/float64).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace mogao::ply {

enum class Type : std::uint8_t { i8, u8, i16, u16, i32, u32, f32, f64 };

struct Property {
    std::string name;
    Type type = Type::f32;  // item type for lists
    bool is_list = false;
    Type count_type = Type::u8;  // lists only
};

struct Element {
    std::string name;
    std::uint64_t count = 0;
    std::vector<Property> props;
};

enum class Format { ascii, binary_le, binary_be };

struct Header {
    Format format = Format::ascii;
    std::vector<Element> elements;
    std::size_t body_offset = 0;  // first byte after the end_header line
    std::size_t body_line = 0;    // line number of that byte (ascii messages)
};

// Thrown by the sources and element readers; read_body prefixes the element name and index.
struct ParseFailure : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// A property type by its PLY name; nullopt for a name PLY does not define.
[[nodiscard]] std::optional<Type> parse_type(std::string_view s);
// Bytes of one value of type t in a binary body.
[[nodiscard]] std::size_t size_of(Type t);
[[nodiscard]] bool is_integer(Type t);

// The header of the PLY file `bytes` (its name `file` in messages): format, elements and their properties, and
// where the body starts. Throws MeshLoadError naming the file, the line and what is wrong (an unknown type or
// format, a property outside an element, a header over 1 MiB or without end_header).
[[nodiscard]] Header parse_header(std::string_view bytes, const std::string& file);

}  // namespace mogao::ply
