// SPDX-License-Identifier: Apache-2.0
#include "appliance/calibration/png_codec.h"

#include <png.h>

#include <csetjmp>
#include <cstring>

#include "appliance/calibration/mpcdi_error.h"
#include "appliance/calibration/pfm_codec.h"

namespace mogao {
namespace {

// libpng reports errors by longjmp. Everything the jump crosses must be trivially destructible,
// so the two functions that call setjmp (png_decode_raw, png_encode_raw) hold only plain C state;
// the std::vectors they fill live in the caller's frame, which the jump never leaves.
struct PngState {
    char message[256] = {};
    const std::uint8_t* input = nullptr;
    std::size_t input_size = 0;
    std::size_t input_pos = 0;
    std::vector<std::uint8_t>* output = nullptr;
};

void on_error(png_structp png, png_const_charp message) {
    auto* state = static_cast<PngState*>(png_get_error_ptr(png));
    std::snprintf(state->message, sizeof state->message, "%s", message);
    png_longjmp(png, 1);
}

void on_warning(png_structp, png_const_charp) {}  // benign (e.g. unknown ancillary chunks)

void read_bytes(png_structp png, png_bytep out, png_size_t count) {
    auto* state = static_cast<PngState*>(png_get_io_ptr(png));
    if (count > state->input_size - state->input_pos) png_error(png, "truncated PNG data");
    std::memcpy(out, state->input + state->input_pos, count);
    state->input_pos += count;
}

void write_bytes(png_structp png, png_bytep data, png_size_t count) {
    auto* state = static_cast<PngState*>(png_get_io_ptr(png));
    state->output->insert(state->output->end(), data, data + count);
}

void flush_nothing(png_structp) {}

struct RawHeader {
    png_uint_32 width = 0;
    png_uint_32 height = 0;
    int bit_depth = 0;
    int color_type = 0;
};

// Phase 1 reads the header; if it is acceptable, `pixels` is sized by the caller-side callback and
// phase 2 fills it. Returns false with state.message set on any libpng error.
bool png_decode_raw(PngState& state, RawHeader& header, std::vector<std::uint8_t>& pixels, std::vector<png_bytep>& rows,
                    bool (*accept)(const RawHeader&, PngState&)) {
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &state, on_error, on_warning);
    if (png == nullptr) {
        std::snprintf(state.message, sizeof state.message, "out of memory");
        return false;
    }
    png_infop info = png_create_info_struct(png);
    if (info == nullptr || setjmp(png_jmpbuf(png)) != 0) {
        png_destroy_read_struct(&png, &info, nullptr);
        return false;
    }
    png_set_read_fn(png, &state, read_bytes);
    png_set_user_limits(png, kMaxMapDimension, kMaxMapDimension);
    png_read_info(png, info);
    header.width = png_get_image_width(png, info);
    header.height = png_get_image_height(png, info);
    header.bit_depth = png_get_bit_depth(png, info);
    header.color_type = png_get_color_type(png, info);
    if (!accept(header, state)) {
        png_destroy_read_struct(&png, &info, nullptr);
        return false;
    }
    png_set_interlace_handling(png);
    png_read_update_info(png, info);
    const png_size_t stride = png_get_rowbytes(png, info);
    pixels.resize(stride * header.height);
    rows.resize(header.height);
    for (png_uint_32 y = 0; y < header.height; ++y) rows[y] = pixels.data() + y * stride;
    png_read_image(png, rows.data());
    png_read_end(png, nullptr);
    png_destroy_read_struct(&png, &info, nullptr);
    return true;
}

bool accept_header(const RawHeader& h, PngState& state) {
    if (h.color_type != PNG_COLOR_TYPE_GRAY && h.color_type != PNG_COLOR_TYPE_RGB) {
        std::snprintf(state.message, sizeof state.message,
                      "colour type %d is not supported (only 0 gray or 2 RGB: MPCDI maps have 1 or 3 components)",
                      h.color_type);
        return false;
    }
    if (h.bit_depth != 8 && h.bit_depth != 16) {
        std::snprintf(state.message, sizeof state.message, "bit depth %d is not supported (only 8 or 16)", h.bit_depth);
        return false;
    }
    return true;
}

bool png_encode_raw(PngState& state, const RawHeader& header, std::vector<png_bytep>& rows) {
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &state, on_error, on_warning);
    if (png == nullptr) {
        std::snprintf(state.message, sizeof state.message, "out of memory");
        return false;
    }
    png_infop info = png_create_info_struct(png);
    if (info == nullptr || setjmp(png_jmpbuf(png)) != 0) {
        png_destroy_write_struct(&png, &info);
        return false;
    }
    png_set_write_fn(png, &state, write_bytes, flush_nothing);
    png_set_IHDR(png, info, header.width, header.height, header.bit_depth, header.color_type, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    png_write_image(png, rows.data());
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    return true;
}

}  // namespace

PngMap decode_png_map(std::span<const std::uint8_t> bytes, const std::string& who) {
    if (bytes.size() < 8 || png_sig_cmp(bytes.data(), 0, 8) != 0) throw MpcdiError(who + ": not a PNG (bad signature)");
    PngState state;
    state.input = bytes.data();
    state.input_size = bytes.size();
    RawHeader header;
    std::vector<std::uint8_t> pixels;
    std::vector<png_bytep> rows;
    if (!png_decode_raw(state, header, pixels, rows, accept_header)) throw MpcdiError(who + ": PNG: " + state.message);
    PngMap map;
    map.size = {static_cast<int>(header.width), static_cast<int>(header.height)};
    map.channels = header.color_type == PNG_COLOR_TYPE_RGB ? 3 : 1;
    map.bit_depth = header.bit_depth;
    const std::size_t count = static_cast<std::size_t>(map.size.pixel_count()) * static_cast<std::size_t>(map.channels);
    map.values.resize(count);
    if (map.bit_depth == 8) {
        for (std::size_t i = 0; i < count; ++i) map.values[i] = pixels[i];
    } else {  // PNG stores 16-bit samples big-endian
        for (std::size_t i = 0; i < count; ++i) {
            map.values[i] = static_cast<std::uint16_t>(pixels[2 * i] << 8 | pixels[2 * i + 1]);
        }
    }
    return map;
}

std::vector<std::uint8_t> encode_png_map(const PngMap& map, const std::string& who) {
    if (map.channels != 1 && map.channels != 3) {
        throw MpcdiError(who + ": PNG channels " + std::to_string(map.channels) + " must be 1 or 3");
    }
    if (map.bit_depth != 8 && map.bit_depth != 16) {
        throw MpcdiError(who + ": PNG bit depth " + std::to_string(map.bit_depth) + " must be 8 or 16");
    }
    if (map.size.width < 1 || map.size.height < 1 || map.size.width > kMaxMapDimension ||
        map.size.height > kMaxMapDimension) {
        throw MpcdiError(who + ": PNG size " + std::to_string(map.size.width) + "x" + std::to_string(map.size.height) +
                         " is outside 1.." + std::to_string(kMaxMapDimension));
    }
    const std::size_t count = static_cast<std::size_t>(map.size.pixel_count()) * static_cast<std::size_t>(map.channels);
    if (map.values.size() != count) {
        throw MpcdiError(who + ": PNG holds " + std::to_string(map.values.size()) + " values, " +
                         std::to_string(count) + " expected");
    }
    const std::size_t bytes_per = map.bit_depth == 8 ? 1 : 2;
    std::vector<std::uint8_t> pixels(count * bytes_per);
    for (std::size_t i = 0; i < count; ++i) {
        const std::uint16_t v = map.values[i];
        if (map.bit_depth == 8) {
            if (v > 255)
                throw MpcdiError(who + ": PNG value " + std::to_string(i) + " = " + std::to_string(v) + " exceeds 255");
            pixels[i] = static_cast<std::uint8_t>(v);
        } else {
            pixels[2 * i] = static_cast<std::uint8_t>(v >> 8);
            pixels[2 * i + 1] = static_cast<std::uint8_t>(v & 0xFF);
        }
    }
    const std::size_t stride =
        static_cast<std::size_t>(map.size.width) * static_cast<std::size_t>(map.channels) * bytes_per;
    std::vector<png_bytep> rows(static_cast<std::size_t>(map.size.height));
    for (std::size_t y = 0; y < rows.size(); ++y) rows[y] = pixels.data() + y * stride;
    std::vector<std::uint8_t> out;
    PngState state;
    state.output = &out;
    RawHeader header{static_cast<png_uint_32>(map.size.width), static_cast<png_uint_32>(map.size.height), map.bit_depth,
                     map.channels == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_GRAY};
    if (!png_encode_raw(state, header, rows)) throw MpcdiError(who + ": PNG encoding failed: " + state.message);
    return out;
}

}  // namespace mogao
