// SPDX-License-Identifier: Apache-2.0
// PLY reader: the header (ply_header.h), two value sources (binary with optional byte swap, ascii tokens) and
// element readers templated on the source, so binary and ascii share one set of rules.
#include "renderfarm/scene/ply_reader.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>

#include "common/srgb.h"
#include "renderfarm/scene/mesh_io.h"
#include "renderfarm/scene/ply_header.h"

namespace mogao {
namespace {

using ply::Element;
using ply::Format;
using ply::Header;
using ply::is_integer;
using ply::parse_header;
using ply::ParseFailure;
using ply::Property;
using ply::size_of;
using ply::Type;

// Binary values, byte-swapped when the file's endianness differs from the host's.
class BinarySource {
public:
    BinarySource(std::string_view data, bool big_endian)
        : data_(data), swap_(big_endian != (std::endian::native == std::endian::big)) {}

    [[nodiscard]] std::size_t remaining() const { return data_.size() - pos_; }

    double real(Type t) {
        switch (t) {
            case Type::i8:
                return get<std::int8_t>();
            case Type::u8:
                return get<std::uint8_t>();
            case Type::i16:
                return get<std::int16_t>();
            case Type::u16:
                return get<std::uint16_t>();
            case Type::i32:
                return get<std::int32_t>();
            case Type::u32:
                return get<std::uint32_t>();
            case Type::f32:
                return get<float>();
            case Type::f64:
                return get<double>();
        }
        throw ParseFailure("bad type");
    }

    std::int64_t integer(Type t) {
        switch (t) {
            case Type::i8:
                return get<std::int8_t>();
            case Type::u8:
                return get<std::uint8_t>();
            case Type::i16:
                return get<std::int16_t>();
            case Type::u16:
                return get<std::uint16_t>();
            case Type::i32:
                return get<std::int32_t>();
            case Type::u32:
                return get<std::uint32_t>();
            case Type::f32:
            case Type::f64:
                break;
        }
        throw ParseFailure("integer expected where the header declares a floating-point type");
    }

    // Throws unless `n` items of type `t` can still follow (so callers may reserve n).
    void check_list(std::uint64_t n, Type t) const {
        if (n > remaining() / size_of(t)) {
            throw ParseFailure(fmt::format("unexpected end of file: list of {} items needs {} bytes, {} remain", n,
                                           n * size_of(t), remaining()));
        }
    }

    void skip(Type t) { advance(size_of(t)); }
    void skip_items(std::uint64_t n, Type t) {
        check_list(n, t);
        pos_ += static_cast<std::size_t>(n) * size_of(t);
    }

private:
    void advance(std::size_t n) {
        if (remaining() < n) throw ParseFailure("unexpected end of file");
        pos_ += n;
    }
    template <class T>
    T get() {
        unsigned char b[sizeof(T)];
        if (remaining() < sizeof(T)) throw ParseFailure("unexpected end of file");
        std::memcpy(b, data_.data() + pos_, sizeof(T));
        pos_ += sizeof(T);
        if (swap_) std::reverse(b, b + sizeof(T));
        T v;
        std::memcpy(&v, b, sizeof(T));
        return v;
    }

    std::string_view data_;
    std::size_t pos_ = 0;
    bool swap_;
};

// Whitespace-separated ascii values; tracks the line number for messages.
class AsciiSource {
public:
    AsciiSource(std::string_view data, std::size_t first_line) : data_(data), line_(first_line) {}

    [[nodiscard]] std::size_t remaining() const { return data_.size() - pos_; }

    double real(Type t) {
        if (is_integer(t)) return static_cast<double>(integer(t));
        const std::string_view tok = token();
        double v = 0.0;
        const auto r = std::from_chars(tok.data(), tok.data() + tok.size(), v);
        if (r.ec != std::errc{} || r.ptr != tok.data() + tok.size()) {
            throw ParseFailure(fmt::format("line {}: '{}' is not a valid number", line_, tok));
        }
        return v;
    }

    std::int64_t integer(Type t) {
        const std::string_view tok = token();
        if (!is_integer(t)) throw ParseFailure("integer expected where the header declares a floating-point type");
        std::int64_t v = 0;
        const auto r = std::from_chars(tok.data(), tok.data() + tok.size(), v);
        if (r.ec != std::errc{} || r.ptr != tok.data() + tok.size()) {
            throw ParseFailure(fmt::format("line {}: '{}' is not a valid integer", line_, tok));
        }
        return v;
    }

    // Every ascii value takes at least one byte, so more items than bytes left cannot follow.
    void check_list(std::uint64_t n, Type) const {
        if (n > remaining()) {
            throw ParseFailure(
                fmt::format("unexpected end of file: list of {} items, only {} bytes remain", n, remaining()));
        }
    }

    void skip(Type) { (void)token(); }
    void skip_items(std::uint64_t n, Type t) {
        check_list(n, t);
        for (std::uint64_t i = 0; i < n; ++i) (void)token();
    }

private:
    std::string_view token() {
        while (pos_ < data_.size() && is_space(data_[pos_])) {
            if (data_[pos_] == '\n') ++line_;
            ++pos_;
        }
        if (pos_ == data_.size()) throw ParseFailure("unexpected end of file");
        const std::size_t start = pos_;
        while (pos_ < data_.size() && !is_space(data_[pos_])) ++pos_;
        return data_.substr(start, pos_ - start);
    }
    static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

    std::string_view data_;
    std::size_t pos_ = 0;
    std::size_t line_;
};

template <class Source>
std::uint64_t list_length(Source& src, const Property& p) {
    const std::int64_t n = src.integer(p.count_type);
    if (n < 0) throw ParseFailure(fmt::format("negative list length {} for '{}'", n, p.name));
    const auto un = static_cast<std::uint64_t>(n);
    if (un > kMaxPlyListLength) {
        throw ParseFailure(
            fmt::format("list '{}' has {} items, more than the limit of {}", p.name, un, kMaxPlyListLength));
    }
    src.check_list(un, p.type);
    return un;
}

template <class Source>
void skip_property(Source& src, const Property& p) {
    if (p.is_list) src.skip_items(list_length(src, p), p.type);
    else src.skip(p.type);
}

float to_float(double v, const Property& p) {
    // Converting a finite double beyond float range is undefined behaviour; non-finite values pass
    // through so that validate_mesh reports them with the vertex index.
    if (std::isfinite(v) && std::abs(v) > static_cast<double>(std::numeric_limits<float>::max())) {
        throw ParseFailure(fmt::format("{} = {} is outside the float range", p.name, v));
    }
    return static_cast<float>(v);
}

// Index of the property named `name` (scalar), or -1.
int find_scalar(const Element& e, std::string_view name) {
    for (std::size_t i = 0; i < e.props.size(); ++i) {
        if (e.props[i].name == name) {
            if (e.props[i].is_list) return -1;
            return static_cast<int>(i);
        }
    }
    return -1;
}

// A colour channel as written by scanners (display sRGB): integer types are codes scaled by the
// type's maximum (uchar / 255, ushort / 65535), floating-point types must already be in [0, 1].
// Returned linear (IEC 61966-2-1 EOTF), as the renderer's albedo is.
double colour_channel(double raw, const Property& p) {
    double v = raw;
    if (p.type == Type::u8) v = raw / 255.0;
    else if (p.type == Type::u16) v = raw / 65535.0;
    else if (is_integer(p.type))
        throw ParseFailure(fmt::format("colour '{}' must be uchar, ushort, float or double", p.name));
    if (!(v >= 0.0 && v <= 1.0)) throw ParseFailure(fmt::format("colour {} = {} is outside [0, 1]", p.name, raw));
    return srgb_decode(v);
}

// Positions are read in double and re-centred on their bounding-box centre (mesh.origin) before
// they are narrowed to float, so coordinates far from the file's origin keep their precision.
template <class Source>
void read_vertices(const Element& e, Source& src, Mesh& mesh, std::uint64_t& i) {
    // role[k]: 0..2 position, 3..5 normal, 6..8 colour, -1 skipped.
    std::vector<int> role(e.props.size(), -1);
    const char* names[9] = {"x", "y", "z", "nx", "ny", "nz", "red", "green", "blue"};
    int found[9];
    for (int r = 0; r < 9; ++r) found[r] = find_scalar(e, names[r]);
    const bool has_normals = found[3] >= 0 && found[4] >= 0 && found[5] >= 0;
    const bool has_colours = found[6] >= 0 && found[7] >= 0 && found[8] >= 0;
    for (int r = 0; r < 9; ++r) {
        if (r >= 3 && r < 6 && !has_normals) continue;
        if (r >= 6 && !has_colours) continue;
        if (found[r] < 0) throw ParseFailure(fmt::format("no scalar property '{}' in the header", names[r]));
        role[static_cast<std::size_t>(found[r])] = r;
    }
    // Capped by bytes left so that a corrupt count cannot make us allocate without bound.
    const auto cap = std::min<std::uint64_t>(e.count, src.remaining() / 3 + 1);
    std::vector<Eigen::Vector3d> wide;
    wide.reserve(static_cast<std::size_t>(cap));
    if (has_normals) mesh.normals.reserve(static_cast<std::size_t>(cap));
    if (has_colours) mesh.colors.reserve(static_cast<std::size_t>(cap));
    double v[9] = {};
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    for (; i < e.count; ++i) {
        for (std::size_t k = 0; k < e.props.size(); ++k) {
            const Property& p = e.props[k];
            const int r = role[k];
            if (r < 0) {
                skip_property(src, p);
                continue;
            }
            const double raw = src.real(p.type);
            if (r < 6) (void)to_float(raw, p);  // the range check: positions end up in float
            v[r] = r < 6 ? raw : colour_channel(raw, p);
        }
        wide.emplace_back(v[0], v[1], v[2]);
        if (wide.back().allFinite()) {
            lo = lo.cwiseMin(wide.back());
            hi = hi.cwiseMax(wide.back());
        }
        if (has_normals)
            mesh.normals.emplace_back(static_cast<float>(v[3]), static_cast<float>(v[4]), static_cast<float>(v[5]));
        if (has_colours)
            mesh.colors.emplace_back(static_cast<float>(v[6]), static_cast<float>(v[7]), static_cast<float>(v[8]));
    }
    mesh.origin = lo.x() <= hi.x() ? Eigen::Vector3d(0.5 * (lo + hi)) : Eigen::Vector3d::Zero();
    mesh.positions.reserve(wide.size());
    for (const Eigen::Vector3d& p : wide) mesh.positions.push_back((p - mesh.origin).cast<float>());
}

// The list property holding vertex indices of a face/tristrips element.
std::size_t index_list(const Element& e) {
    for (std::size_t k = 0; k < e.props.size(); ++k) {
        const Property& p = e.props[k];
        if (p.name == "vertex_indices" || p.name == "vertex_index") {
            if (!p.is_list || !is_integer(p.type))
                throw ParseFailure(fmt::format("'{}' must be a list of integers", p.name));
            return k;
        }
    }
    throw ParseFailure("no 'vertex_indices' list property in the header");
}

std::uint32_t checked_index(std::int64_t v, std::uint64_t vertex_count) {
    if (v < 0 || static_cast<std::uint64_t>(v) >= vertex_count) {
        throw ParseFailure(fmt::format("vertex index {} out of range ({} vertices)", v, vertex_count));
    }
    return static_cast<std::uint32_t>(v);
}

template <class Source>
void read_faces(const Element& e, Source& src, Mesh& mesh, std::uint64_t vertex_count, std::uint64_t& i) {
    const std::size_t list = index_list(e);
    mesh.triangles.reserve(mesh.triangles.size() +
                           static_cast<std::size_t>(std::min<std::uint64_t>(e.count, src.remaining() / 4 + 1)));
    std::vector<std::uint32_t> poly;
    for (; i < e.count; ++i) {
        for (std::size_t k = 0; k < e.props.size(); ++k) {
            const Property& p = e.props[k];
            if (k != list) {
                skip_property(src, p);
                continue;
            }
            const std::uint64_t n = list_length(src, p);
            if (n < 3) throw ParseFailure(fmt::format("polygon with {} vertices (at least 3 needed)", n));
            poly.clear();
            for (std::uint64_t j = 0; j < n; ++j) poly.push_back(checked_index(src.integer(p.type), vertex_count));
            for (std::size_t j = 1; j + 1 < poly.size(); ++j) mesh.triangles.push_back({poly[0], poly[j], poly[j + 1]});
        }
    }
}

template <class Source>
void read_tristrips(const Element& e, Source& src, Mesh& mesh, std::uint64_t vertex_count, std::uint64_t& i) {
    const std::size_t list = index_list(e);
    for (; i < e.count; ++i) {
        for (std::size_t k = 0; k < e.props.size(); ++k) {
            const Property& p = e.props[k];
            if (k != list) {
                skip_property(src, p);
                continue;
            }
            const std::uint64_t n = list_length(src, p);
            mesh.triangles.reserve(mesh.triangles.size() + static_cast<std::size_t>(n));
            // Triangle t of a strip is (s[t], s[t+1], s[t+2]) for even t and (s[t+1], s[t], s[t+2])
            // for odd t, so that all triangles of a strip keep the first one's orientation.
            std::uint32_t a = 0, b = 0;
            std::uint64_t in_strip = 0;
            for (std::uint64_t j = 0; j < n; ++j) {
                const std::int64_t raw = src.integer(p.type);
                if (raw == -1) {
                    in_strip = 0;
                    continue;
                }
                std::uint32_t c = 0;
                try {
                    c = checked_index(raw, vertex_count);
                } catch (const ParseFailure& f) {
                    throw ParseFailure(fmt::format("item {}: {}", j, f.what()));
                }
                if (in_strip >= 2 && a != b && b != c && a != c) {
                    if (in_strip % 2 == 0) mesh.triangles.push_back({a, b, c});
                    else mesh.triangles.push_back({b, a, c});
                }
                a = b;
                b = c;
                ++in_strip;
            }
        }
    }
}

// A corrupt count (e.g. 4e9 vertices) fails here, before anything is reserved: each element of
// fixed size must fit in the bytes after the header. Lists count with their length field only.
void check_binary_sizes(const Header& h, std::size_t body_bytes, const std::string& file) {
    std::uint64_t before = 0;  // minimum bytes of the elements before this one
    bool exact = true;         // `before` is exact (no lists so far)
    for (const Element& e : h.elements) {
        std::uint64_t min_size = 0;
        bool fixed = true;
        for (const Property& p : e.props) {
            min_size += size_of(p.is_list ? p.count_type : p.type);
            fixed = fixed && !p.is_list;
        }
        if (min_size == 0) continue;
        const std::uint64_t avail = body_bytes - before;
        if (e.count > avail / min_size) {
            if (exact && fixed) {
                throw MeshLoadError(file, fmt::format("{} {}: unexpected end of file (header declares {} '{}' elements "
                                                      "of {} bytes; {} bytes follow the header)",
                                                      e.name, avail / min_size, e.count, e.name, min_size, body_bytes));
            }
            throw MeshLoadError(file, fmt::format("element '{}': unexpected end of file (header declares {} elements "
                                                  "of at least {} bytes; {} bytes follow the header)",
                                                  e.name, e.count, min_size, body_bytes));
        }
        before += e.count * min_size;
        exact = exact && fixed;
    }
}

template <class Source>
void read_body(const Header& h, Source& src, Mesh& mesh, const std::string& file) {
    std::uint64_t vertex_count = 0;
    bool have_vertex = false;
    for (const Element& e : h.elements) {
        if (e.name == "vertex") {
            if (have_vertex) throw MeshLoadError(file, "more than one 'vertex' element");
            have_vertex = true;
            vertex_count = e.count;
        }
    }
    if (!have_vertex) throw MeshLoadError(file, "no 'vertex' element in the header");
    if (vertex_count > std::numeric_limits<std::uint32_t>::max()) {
        throw MeshLoadError(file, fmt::format("{} vertices exceed the 32-bit index limit", vertex_count));
    }
    for (const Element& e : h.elements) {
        std::uint64_t i = 0;
        try {
            if (e.name == "vertex") read_vertices(e, src, mesh, i);
            else if (e.name == "face") read_faces(e, src, mesh, vertex_count, i);
            else if (e.name == "tristrips") read_tristrips(e, src, mesh, vertex_count, i);
            else if (!e.props.empty()) {
                // Elements without properties take no bytes; do not loop over a huge count.
                for (; i < e.count; ++i) {
                    for (const Property& p : e.props) skip_property(src, p);
                }
            }
        } catch (const ParseFailure& f) {
            throw MeshLoadError(file, fmt::format("{} {}: {}", e.name, i, f.what()));
        }
    }
}

}  // namespace

Mesh parse_ply(std::string_view bytes, const std::string& name) {
    const Header h = parse_header(bytes, name);
    const std::string_view body = bytes.substr(h.body_offset);
    Mesh mesh;
    mesh.source = name;
    if (h.format == Format::ascii) {
        AsciiSource src(body, h.body_line);
        read_body(h, src, mesh, name);
    } else {
        check_binary_sizes(h, body.size(), name);
        BinarySource src(body, h.format == Format::binary_be);
        read_body(h, src, mesh, name);
    }
    return mesh;
}

Mesh read_ply(const std::filesystem::path& path) {
    const std::string name = path.string();
    std::ifstream in(path, std::ios::binary);
    std::error_code ec;
    const auto size = std::filesystem::file_size(path, ec);
    if (!in || ec) throw MeshLoadError(name, "cannot open file");
    std::string bytes(static_cast<std::size_t>(size), '\0');
    if (!in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()))) throw MeshLoadError(name, "read error");
    return parse_ply(bytes, name);
}

}  // namespace mogao
