// SPDX-License-Identifier: Apache-2.0
#include "drivers/camera/pixel_format.h"

#include <cstddef>
#include <cstring>

namespace mogao {
namespace {

// Shared checks of both packed formats: sizes, stride and buffer length.
Status check_layout(const char* format, std::size_t available, int width, int height, int bytes_per_line,
                    int bytes_per_pixel) {
    const auto where = std::string(format) + " buffer: ";
    if (width < 1 || width > kMaxCaptureDimension || height < 1 || height > kMaxCaptureDimension) {
        return make_error(EINVAL, where + "size " + std::to_string(width) + "x" + std::to_string(height) +
                                      " outside [1, " + std::to_string(kMaxCaptureDimension) + "] per side");
    }
    const long long row = static_cast<long long>(width) * bytes_per_pixel;
    if (bytes_per_line < row) {
        return make_error(EINVAL, where + "bytes_per_line " + std::to_string(bytes_per_line) +
                                      " is below the row size " + std::to_string(row));
    }
    // The last row needs only `row` bytes, not a full stride (drivers may omit the padding).
    const long long needed = static_cast<long long>(bytes_per_line) * (height - 1) + row;
    if (static_cast<long long>(available) < needed) {
        return make_error(EINVAL, where + std::to_string(available) + " bytes, " + std::to_string(needed) +
                                      " needed for " + std::to_string(width) + "x" + std::to_string(height));
    }
    return {};
}

void resize(GrayImage& out, int width, int height) {
    out.width = width;
    out.height = height;
    out.pixels.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
}

}  // namespace

std::string pixel_format_name(CaptureFormat format) {
    switch (format) {
        case CaptureFormat::grey:
            return "GREY";
        case CaptureFormat::yuyv:
            return "YUYV";
        case CaptureFormat::mjpeg:
            return "MJPG";
        case CaptureFormat::image_file:
            return "file";
    }
    return "?";
}

std::string fourcc_name(std::uint32_t fourcc) {
    std::string name(4, '?');
    for (int i = 0; i < 4; ++i) {
        const auto c = static_cast<char>((fourcc >> (8 * i)) & 0xffU);
        if (c >= 0x20 && c < 0x7f) name[static_cast<std::size_t>(i)] = c;
    }
    return name;
}

Status grey_from_grey(std::span<const std::uint8_t> data, int width, int height, int bytes_per_line, GrayImage& out) {
    if (Status s = check_layout("GREY", data.size(), width, height, bytes_per_line, 1); !s) return s;
    resize(out, width, height);
    const auto w = static_cast<std::size_t>(width);
    for (int y = 0; y < height; ++y) {
        std::memcpy(out.pixels.data() + static_cast<std::size_t>(y) * w,
                    data.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(bytes_per_line), w);
    }
    return {};
}

Status grey_from_yuyv(std::span<const std::uint8_t> data, int width, int height, int bytes_per_line, GrayImage& out) {
    if (width % 2 != 0) {
        return make_error(EINVAL, "YUYV buffer: width " + std::to_string(width) + " is odd (4:2:2 pairs pixels)");
    }
    if (Status s = check_layout("YUYV", data.size(), width, height, bytes_per_line, 2); !s) return s;
    resize(out, width, height);
    const auto w = static_cast<std::size_t>(width);
    for (int y = 0; y < height; ++y) {
        const std::uint8_t* src = data.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(bytes_per_line);
        std::uint8_t* dst = out.pixels.data() + static_cast<std::size_t>(y) * w;
        for (std::size_t x = 0; x < w; ++x) dst[x] = src[2 * x];
    }
    return {};
}

}  // namespace mogao
