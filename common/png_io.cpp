// SPDX-License-Identifier: Apache-2.0
#include "common/png_io.h"

#include <png.h>

#include <cctype>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/file_io.h"

namespace mogao {
namespace {

std::string quoted(const std::filesystem::path& path) { return "'" + path.string() + "'"; }

// Frees libpng's state on every exit path (png_image_free is a no-op once finish_read succeeded).
struct PngImageGuard {
    png_image image{};
    PngImageGuard() {
        image.version = PNG_IMAGE_VERSION;
        image.opaque = nullptr;
    }
    ~PngImageGuard() { png_image_free(&image); }
    PngImageGuard(const PngImageGuard&) = delete;
    PngImageGuard& operator=(const PngImageGuard&) = delete;
};

// The project's reader/writer convention (docs/architecture.md) is one typed error per direction,
// so file-system failures (std::system_error from file_io) are re-thrown as DecodeError/EncodeError
// with the same message, which already names the path and the errno reason.
std::vector<std::uint8_t> read_or_throw(const std::filesystem::path& path, const char* who) {
    try {
        return read_file_bytes(path);
    } catch (const std::runtime_error& e) {
        throw DecodeError(std::string(who) + ": " + e.what());
    }
}

void write_or_throw(const std::filesystem::path& path, const std::vector<std::uint8_t>& bytes, const char* who) {
    try {
        write_file_atomically(path, bytes);
    } catch (const std::runtime_error& e) {
        throw EncodeError(std::string(who) + ": " + e.what());
    }
}

}  // namespace

// The simplified API (png_image_*) is used instead of png_create_*_struct because it reports
// errors as return values: the classic API longjmp()s out of libpng, which skips C++ destructors.
void write_png(const std::filesystem::path& path, const Rgb8Image& image, PngCompression compression) {
    require_valid_image(image, "write_png " + quoted(path));
    PngImageGuard png;
    png.image.width = static_cast<png_uint_32>(image.size.width);
    png.image.height = static_cast<png_uint_32>(image.size.height);
    png.image.format = PNG_FORMAT_RGB;
    if (compression == PngCompression::fast) png.image.flags |= PNG_IMAGE_FLAG_FAST;
    if (image.size.width > std::numeric_limits<png_int_32>::max() / 3) {
        throw EncodeError("write_png " + quoted(path) + ": width " + std::to_string(image.size.width) +
                          " is too large for a PNG row");
    }
    const png_int_32 stride = image.size.width * 3;

    // PNG_IMAGE_PNG_SIZE_MAX bounds the stored size, so one compression pass is enough.
    png_alloc_size_t size = PNG_IMAGE_PNG_SIZE_MAX(png.image);
    std::vector<std::uint8_t> bytes(size);
    if (png_image_write_to_memory(&png.image, bytes.data(), &size, 0, image.pixels.data(), stride, nullptr) == 0) {
        throw EncodeError("write_png " + quoted(path) + ": libpng: " + png.image.message);
    }
    bytes.resize(size);
    write_or_throw(path, bytes, "write_png");
}

Rgb8Image read_png(const std::filesystem::path& path) {
    const std::vector<std::uint8_t> bytes = read_or_throw(path, "read_png");
    PngImageGuard png;
    if (png_image_begin_read_from_memory(&png.image, bytes.data(), bytes.size()) == 0) {
        throw DecodeError("read_png " + quoted(path) + ": " + png.image.message);
    }
    if (png.image.width > static_cast<png_uint_32>(kMaxDecodedDimension) ||
        png.image.height > static_cast<png_uint_32>(kMaxDecodedDimension)) {
        throw DecodeError("read_png " + quoted(path) + ": size " + std::to_string(png.image.width) + "x" +
                          std::to_string(png.image.height) + " exceeds " + std::to_string(kMaxDecodedDimension) +
                          " per side");
    }
    png.image.format = PNG_FORMAT_RGB;
    Rgb8Image out(ImageSize{static_cast<int>(png.image.width), static_cast<int>(png.image.height)});
    const png_color black{0, 0, 0};
    const auto stride = static_cast<png_int_32>(out.size.width * 3);
    if (png_image_finish_read(&png.image, &black, out.pixels.data(), stride, nullptr) == 0) {
        throw DecodeError("read_png " + quoted(path) + ": " + png.image.message);
    }
    return out;
}

void write_ppm(const std::filesystem::path& path, const Rgb8Image& image) {
    require_valid_image(image, "write_ppm " + quoted(path));
    const std::string header =
        "P6\n" + std::to_string(image.size.width) + " " + std::to_string(image.size.height) + "\n255\n";
    std::vector<std::uint8_t> bytes(header.begin(), header.end());
    bytes.insert(bytes.end(), image.pixels.begin(), image.pixels.end());
    write_or_throw(path, bytes, "write_ppm");
}

Rgb8Image read_ppm(const std::filesystem::path& path) {
    const std::vector<std::uint8_t> bytes = read_or_throw(path, "read_ppm");
    const std::string who = "read_ppm " + quoted(path) + ": ";
    std::size_t pos = 0;
    auto fail = [&](const std::string& why) -> DecodeError { return DecodeError(who + why); };

    // Netpbm header: magic, then three decimal fields separated by whitespace and '#'-to-end-of-line
    // comments, then exactly one whitespace byte before the raster.
    auto skip_space_and_comments = [&] {
        while (pos < bytes.size()) {
            if (bytes[pos] == '#') {
                while (pos < bytes.size() && bytes[pos] != '\n') ++pos;
            } else if (std::isspace(bytes[pos]) != 0) {
                ++pos;
            } else {
                break;
            }
        }
    };
    auto read_field = [&](const char* name) -> int {
        skip_space_and_comments();
        long long value = 0;
        const std::size_t start = pos;
        while (pos < bytes.size() && std::isdigit(bytes[pos]) != 0) {
            value = value * 10 + (bytes[pos] - '0');
            if (value > 1'000'000) throw fail(std::string(name) + " is absurdly large");
            ++pos;
        }
        if (pos == start) throw fail(std::string("header has no ") + name);
        return static_cast<int>(value);
    };

    if (bytes.size() < 2 || bytes[0] != 'P' || bytes[1] != '6') {
        throw fail("not a binary PPM (expected magic 'P6')");
    }
    pos = 2;
    const int width = read_field("width");
    const int height = read_field("height");
    const int maxval = read_field("maxval");
    if (pos >= bytes.size() || std::isspace(bytes[pos]) == 0) throw fail("header is not followed by whitespace");
    ++pos;
    if (maxval != 255) throw fail("maxval " + std::to_string(maxval) + " is not supported (only 255)");
    if (width <= 0 || height <= 0 || width > kMaxDecodedDimension || height > kMaxDecodedDimension) {
        throw fail("size " + std::to_string(width) + "x" + std::to_string(height) + " is outside 1.." +
                   std::to_string(kMaxDecodedDimension) + " per side");
    }
    Rgb8Image image(ImageSize{width, height});
    if (bytes.size() - pos < image.pixels.size()) {
        throw fail("truncated: " + std::to_string(bytes.size() - pos) + " raster bytes, " +
                   std::to_string(image.pixels.size()) + " expected");
    }
    std::memcpy(image.pixels.data(), bytes.data() + pos, image.pixels.size());
    return image;
}

}  // namespace mogao
