// SPDX-License-Identifier: Apache-2.0
#include "drivers/camera/image_file.h"

#include <fcntl.h>
#include <png.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "common/unique_fd.h"
#include "drivers/camera/mjpeg_decoder.h"
#include "drivers/camera/pixel_format.h"

namespace mogao {
namespace {

Result<std::vector<std::uint8_t>> read_whole_file(const std::filesystem::path& path) {
    UniqueFd fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
    if (!fd.valid()) return errno_error("open " + path.string());
    struct stat st {};
    if (::fstat(fd.get(), &st) != 0) return errno_error("stat " + path.string());
    if (!S_ISREG(st.st_mode)) return make_error(EINVAL, path.string() + ": not a regular file");
    if (static_cast<std::uintmax_t>(st.st_size) > kMaxImageFileBytes) {
        return make_error(EFBIG, path.string() + ": " + std::to_string(st.st_size) + " bytes exceeds the " +
                                     std::to_string(kMaxImageFileBytes) + "-byte limit for an image file");
    }
    std::vector<std::uint8_t> bytes(static_cast<std::size_t>(st.st_size));
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::read(fd.get(), bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) return errno_error("read " + path.string());
        if (n == 0) break;  // file shrank while reading: decode what is there, the decoder reports truncation
        done += static_cast<std::size_t>(n);
    }
    bytes.resize(done);
    return bytes;
}

Status check_size(const std::filesystem::path& path, std::uint64_t w, std::uint64_t h) {
    if (w == 0 || h == 0 || w > kMaxCaptureDimension || h > kMaxCaptureDimension) {
        return make_error(EINVAL, path.string() + ": " + std::to_string(w) + "x" + std::to_string(h) +
                                      " is outside 1.." + std::to_string(kMaxCaptureDimension) + " per side");
    }
    return {};
}

// BT.601 luma on the encoded values (what a JPEG's Y channel holds, ITU-T T.871), so colour PNG and
// colour JPEG frames of one scene give the same grey.
std::uint8_t luma601(double r, double g, double b) {
    return static_cast<std::uint8_t>(std::lround(std::clamp(0.299 * r + 0.587 * g + 0.114 * b, 0.0, 255.0)));
}

Result<GrayImage> decode_png(const std::filesystem::path& path, std::span<const std::uint8_t> bytes) {
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    // The simplified API reports errors through png.message and a 0 return, never longjmp to us.
    if (png_image_begin_read_from_memory(&png, bytes.data(), bytes.size()) == 0) {
        return make_error(EBADMSG, path.string() + ": bad PNG: " + png.message);
    }
    if (auto ok = check_size(path, png.width, png.height); !ok) {
        png_image_free(&png);
        return ok.error();
    }
    // The simplified API treats 16-bit samples as linear light and would re-encode them to sRGB when
    // asked for 8 bits; camera PNGs are not linear, so 16-bit files are read as 16-bit (no
    // conversion) and scaled by 255/65535 here, like PGM. Colour is read as RGB and reduced with
    // luma601. Alpha is composited on black.
    const bool wide = (png.format & PNG_FORMAT_FLAG_LINEAR) != 0;
    const bool colour = (png.format & PNG_FORMAT_FLAG_COLOR) != 0;
    png.format =
        colour ? (wide ? PNG_FORMAT_LINEAR_RGB : PNG_FORMAT_RGB) : (wide ? PNG_FORMAT_LINEAR_Y : PNG_FORMAT_GRAY);
    const std::size_t count = static_cast<std::size_t>(png.width) * png.height;
    std::vector<std::uint8_t> buffer(PNG_IMAGE_SIZE(png));
    png_color black{0, 0, 0};
    if (png_image_finish_read(&png, wide ? nullptr : &black, buffer.data(), 0, nullptr) == 0) {
        const std::string why = png.message;
        png_image_free(&png);
        return make_error(EBADMSG, path.string() + ": bad PNG: " + why);
    }
    GrayImage image(static_cast<int>(png.width), static_cast<int>(png.height));
    auto sample = [&](std::size_t i) -> double {  // 0..255, not rounded
        if (!wide) return buffer[i];
        std::uint16_t v;
        std::memcpy(&v, buffer.data() + 2 * i, 2);  // native byte order (libpng manual)
        return v * (255.0 / 65535.0);
    };
    for (std::size_t p = 0; p < count; ++p) {
        image.pixels[p] = colour ? luma601(sample(3 * p), sample(3 * p + 1), sample(3 * p + 2))
                                 : static_cast<std::uint8_t>(std::lround(sample(p)));
    }
    return image;
}

// Netpbm pgm(5): "P5" whitespace width whitespace height whitespace maxval one-whitespace raster;
// '#' comments run to the end of a line in the header.
Result<GrayImage> decode_pgm(const std::filesystem::path& path, std::span<const std::uint8_t> bytes) {
    std::size_t pos = 2;
    auto header_number = [&](const char* field, std::uint64_t limit) -> Result<std::uint64_t> {
        while (pos < bytes.size() && (std::isspace(bytes[pos]) || bytes[pos] == '#')) {
            if (bytes[pos] == '#') {
                while (pos < bytes.size() && bytes[pos] != '\n') ++pos;
            } else {
                ++pos;
            }
        }
        std::uint64_t value = 0;
        const std::size_t start = pos;
        while (pos < bytes.size() && std::isdigit(bytes[pos]) && pos - start < 10)
            value = value * 10 + (bytes[pos++] - '0');
        if (pos == start || value == 0 || value > limit) {
            return make_error(EBADMSG, path.string() + ": bad PGM header: " + field + " missing or outside 1.." +
                                           std::to_string(limit));
        }
        return value;
    };
    auto w = header_number("width", kMaxCaptureDimension);
    if (!w) return w.error();
    auto h = header_number("height", kMaxCaptureDimension);
    if (!h) return h.error();
    auto maxval = header_number("maxval", 65535);
    if (!maxval) return maxval.error();
    if (pos >= bytes.size() || !std::isspace(bytes[pos])) {
        return make_error(EBADMSG, path.string() + ": bad PGM header: no whitespace after maxval");
    }
    ++pos;
    const std::size_t sample_bytes = *maxval > 255 ? 2 : 1;
    const std::size_t count = static_cast<std::size_t>(*w) * static_cast<std::size_t>(*h);
    if (bytes.size() - pos < count * sample_bytes) {
        return make_error(EBADMSG, path.string() + ": truncated PGM: " + std::to_string(bytes.size() - pos) +
                                       " raster bytes for " + std::to_string(*w) + "x" + std::to_string(*h) +
                                       " (need " + std::to_string(count * sample_bytes) + ")");
    }
    GrayImage image(static_cast<int>(*w), static_cast<int>(*h));
    const double scale = 255.0 / static_cast<double>(*maxval);
    for (std::size_t i = 0; i < count; ++i) {
        const std::uint8_t* s = bytes.data() + pos + i * sample_bytes;
        const unsigned v = sample_bytes == 2 ? (unsigned{s[0]} << 8) | s[1] : s[0];  // 16-bit samples are big-endian
        if (v > *maxval) {
            return make_error(EBADMSG, path.string() + ": PGM sample " + std::to_string(v) + " at pixel " +
                                           std::to_string(i) + " exceeds maxval " + std::to_string(*maxval));
        }
        image.pixels[i] = static_cast<std::uint8_t>(std::lround(v * scale));
    }
    return image;
}

}  // namespace

Result<GrayImage> read_gray_image(const std::filesystem::path& path) {
    auto bytes = read_whole_file(path);
    if (!bytes) return bytes.error();
    const std::vector<std::uint8_t>& b = *bytes;
    static constexpr std::uint8_t kPngMagic[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    if (b.size() >= 8 && std::memcmp(b.data(), kPngMagic, 8) == 0) return decode_png(path, b);
    if (b.size() >= 3 && b[0] == 'P' && b[1] == '5' && std::isspace(b[2])) return decode_pgm(path, b);
    if (b.size() >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF) {
        auto decoder = MjpegDecoder::create();
        if (!decoder) return decoder.error();
        GrayImage image;
        if (auto ok = decoder->decode_grey(b, image); !ok) {
            return make_error(ok.error().code, path.string() + ": " + ok.error().message);
        }
        return image;
    }
    return make_error(
        EBADMSG, path.string() + ": not a PNG, binary PGM (P5) or JPEG file (" + std::to_string(b.size()) + " bytes)");
}

}  // namespace mogao
