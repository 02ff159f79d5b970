// SPDX-License-Identifier: Apache-2.0
#include "drivers/camera/pixel_format.h"

#include <linux/videodev2.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstring>

namespace mogao {
namespace {

// Shared checks of one plane: sizes, stride and buffer length. `row` is the bytes of one row.
Status check_plane(const std::string& where, std::size_t available, int width, int height, int bytes_per_line,
                   long long row) {
    if (width < 1 || width > kMaxCaptureDimension || height < 1 || height > kMaxCaptureDimension) {
        return make_error(EINVAL, where + "size " + std::to_string(width) + "x" + std::to_string(height) +
                                      " outside [1, " + std::to_string(kMaxCaptureDimension) + "] per side");
    }
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

Status check_layout(const char* format, std::size_t available, int width, int height, int bytes_per_line,
                    int bytes_per_pixel) {
    return check_plane(std::string(format) + " buffer: ", available, width, height, bytes_per_line,
                       static_cast<long long>(width) * bytes_per_pixel);
}

void resize(GrayImage& out, int width, int height) {
    out.width = width;
    out.height = height;
    out.pixels.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
}

void resize(Rgb8Image& out, int width, int height) {
    out.size = ImageSize{width, height};
    out.pixels.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3);
}

// The conversion of one encoding in 16.16 fixed point (formulas in pixel_format.h).
struct YcbcrToRgb {
    int y_offset = 0;
    int y_scale = 0;
    int cr_r = 0;
    int cb_g = 0;
    int cr_g = 0;
    int cb_b = 0;

    explicit YcbcrToRgb(YcbcrEncoding e) {
        double kr = 0.299;
        double kb = 0.114;
        switch (e.matrix) {
            case YcbcrMatrix::bt601:
                break;
            case YcbcrMatrix::bt709:
                kr = 0.2126, kb = 0.0722;
                break;
            case YcbcrMatrix::bt2020:
                kr = 0.2627, kb = 0.0593;
                break;
            case YcbcrMatrix::smpte240m:
                kr = 0.212, kb = 0.087;
                break;
        }
        const double kg = 1.0 - kr - kb;
        const bool limited = e.range == YcbcrRange::limited;
        const double ys = limited ? 255.0 / 219.0 : 1.0;
        const double cs = limited ? 255.0 / 224.0 : 1.0;
        const auto fixed = [](double v) { return static_cast<int>(std::lround(v * 65536.0)); };
        y_offset = limited ? 16 : 0;
        y_scale = fixed(ys);
        cr_r = fixed(2.0 * (1.0 - kr) * cs);
        cb_b = fixed(2.0 * (1.0 - kb) * cs);
        cb_g = fixed(2.0 * kb * (1.0 - kb) / kg * cs);
        cr_g = fixed(2.0 * kr * (1.0 - kr) / kg * cs);
    }

    static std::uint8_t clamp(int v) { return static_cast<std::uint8_t>(std::clamp((v + 32768) >> 16, 0, 255)); }

    void operator()(int y, int cb, int cr, std::uint8_t* rgb) const {
        const int yy = (y - y_offset) * y_scale;
        const int u = cb - 128;
        const int v = cr - 128;
        rgb[0] = clamp(yy + cr_r * v);
        rgb[1] = clamp(yy - cb_g * u - cr_g * v);
        rgb[2] = clamp(yy + cb_b * u);
    }
};

// The planes of a 4:2:0 frame, resolved from one buffer or several.
struct Yuv420View {
    PlaneBytes y;
    std::span<const std::uint8_t> cb;  // first Cb byte
    std::span<const std::uint8_t> cr;  // first Cr byte
    int chroma_bytes_per_line = 0;
    int chroma_step = 1;  // 2 for interleaved (semi-planar) chroma
};

Result<Yuv420View> yuv420_view(CaptureFormat format, std::span<const PlaneBytes> planes, int width, int height) {
    const std::string name = pixel_format_name(format);
    const bool semi = format == CaptureFormat::nv12 || format == CaptureFormat::nv21;
    const bool cr_first = format == CaptureFormat::nv21 || format == CaptureFormat::yvu420;
    const int cw = (width + 1) / 2;
    const int ch = (height + 1) / 2;
    const std::size_t expected_planes = semi ? 2 : 3;
    if (planes.size() != 1 && planes.size() != expected_planes) {
        return make_error(EINVAL, name + " buffer: " + std::to_string(planes.size()) + " planes, expected 1 or " +
                                      std::to_string(expected_planes));
    }
    Yuv420View v;
    v.y = planes[0];
    v.chroma_step = semi ? 2 : 1;
    if (Status s = check_plane(name + " buffer, Y' plane: ", v.y.data.size(), width, height, v.y.bytes_per_line, width);
        !s)
        return s.error();
    std::array<PlaneBytes, 2> chroma;  // in buffer order
    if (planes.size() == 1) {
        // One buffer (V4L2 NV12 / YU12): chroma follows a full-stride luma plane.
        const std::size_t luma = static_cast<std::size_t>(v.y.bytes_per_line) * static_cast<std::size_t>(height);
        const int stride = semi ? v.y.bytes_per_line : v.y.bytes_per_line / 2;
        const std::span<const std::uint8_t> rest = v.y.data.subspan(std::min(luma, v.y.data.size()));
        const std::size_t plane_bytes = static_cast<std::size_t>(stride) * static_cast<std::size_t>(ch);
        chroma[0] = {rest.first(std::min(rest.size(), semi ? rest.size() : plane_bytes)), stride};
        chroma[1] = semi ? chroma[0] : PlaneBytes{rest.subspan(std::min(rest.size(), plane_bytes)), stride};
    } else {
        chroma[0] = planes[1];
        chroma[1] = semi ? planes[1] : planes[2];
    }
    const long long row = semi ? 2LL * cw : cw;
    for (std::size_t i = 0; i < (semi ? 1U : 2U); ++i) {
        const std::string where = name + " buffer, chroma plane " + std::to_string(i + 1) + ": ";
        if (Status s = check_plane(where, chroma[i].data.size(), cw, ch, chroma[i].bytes_per_line, row); !s)
            return s.error();
    }
    v.chroma_bytes_per_line = chroma[0].bytes_per_line;
    if (!semi && chroma[1].bytes_per_line != chroma[0].bytes_per_line) {
        return make_error(EINVAL, name + " buffer: chroma planes have different bytes_per_line (" +
                                      std::to_string(chroma[0].bytes_per_line) + ", " +
                                      std::to_string(chroma[1].bytes_per_line) + ")");
    }
    if (semi) {
        v.cb = chroma[0].data.subspan(cr_first ? 1 : 0);
        v.cr = chroma[0].data.subspan(cr_first ? 0 : 1);
    } else {
        v.cb = chroma[cr_first ? 1 : 0].data;
        v.cr = chroma[cr_first ? 0 : 1].data;
    }
    return v;
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
        case CaptureFormat::nv12:
            return "NV12";
        case CaptureFormat::nv21:
            return "NV21";
        case CaptureFormat::yuv420:
            return "YU12";
        case CaptureFormat::yvu420:
            return "YV12";
        case CaptureFormat::rgb24:
            return "RGB3";
        case CaptureFormat::bgr24:
            return "BGR3";
    }
    return "?";
}

bool is_yuv420(CaptureFormat format) {
    return format == CaptureFormat::nv12 || format == CaptureFormat::nv21 || format == CaptureFormat::yuv420 ||
           format == CaptureFormat::yvu420;
}

std::string fourcc_name(std::uint32_t fourcc) {
    std::string name(4, '?');
    for (int i = 0; i < 4; ++i) {
        const auto c = static_cast<char>((fourcc >> (8 * i)) & 0xffU);
        if (c >= 0x20 && c < 0x7f) name[static_cast<std::size_t>(i)] = c;
    }
    return name;
}

YcbcrEncoding ycbcr_encoding_from_v4l2(std::uint32_t colorspace, std::uint32_t ycbcr_enc, std::uint32_t quantization) {
    YcbcrEncoding e;
    std::uint32_t enc = ycbcr_enc;
    if (enc == V4L2_YCBCR_ENC_DEFAULT) {
        enc = colorspace == V4L2_COLORSPACE_REC709      ? V4L2_YCBCR_ENC_709
              : colorspace == V4L2_COLORSPACE_BT2020    ? V4L2_YCBCR_ENC_BT2020
              : colorspace == V4L2_COLORSPACE_SMPTE240M ? V4L2_YCBCR_ENC_SMPTE240M
                                                        : V4L2_YCBCR_ENC_601;
    }
    switch (enc) {
        case V4L2_YCBCR_ENC_709:
        case V4L2_YCBCR_ENC_XV709:
            e.matrix = YcbcrMatrix::bt709;
            break;
        case V4L2_YCBCR_ENC_BT2020:
        case V4L2_YCBCR_ENC_BT2020_CONST_LUM:
            e.matrix = YcbcrMatrix::bt2020;
            break;
        case V4L2_YCBCR_ENC_SMPTE240M:
            e.matrix = YcbcrMatrix::smpte240m;
            break;
        default:
            e.matrix = YcbcrMatrix::bt601;
            break;
    }
    if (quantization == V4L2_QUANTIZATION_DEFAULT) {
        e.range = colorspace == V4L2_COLORSPACE_JPEG ? YcbcrRange::full : YcbcrRange::limited;
    } else {
        e.range = quantization == V4L2_QUANTIZATION_FULL_RANGE ? YcbcrRange::full : YcbcrRange::limited;
    }
    return e;
}

std::string ycbcr_encoding_name(YcbcrEncoding encoding) {
    const char* matrix = "BT.601";
    switch (encoding.matrix) {
        case YcbcrMatrix::bt601:
            break;
        case YcbcrMatrix::bt709:
            matrix = "BT.709";
            break;
        case YcbcrMatrix::bt2020:
            matrix = "BT.2020";
            break;
        case YcbcrMatrix::smpte240m:
            matrix = "SMPTE 240M";
            break;
    }
    return std::string(matrix) + (encoding.range == YcbcrRange::full ? " full" : " limited");
}

void rgb_from_ycbcr(std::uint8_t y, std::uint8_t cb, std::uint8_t cr, YcbcrEncoding encoding, std::uint8_t* rgb) {
    const YcbcrToRgb convert(encoding);
    convert(y, cb, cr, rgb);
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

Status rgb_from_yuyv(std::span<const std::uint8_t> data, int width, int height, int bytes_per_line,
                     YcbcrEncoding encoding, Rgb8Image& out) {
    if (width % 2 != 0) {
        return make_error(EINVAL, "YUYV buffer: width " + std::to_string(width) + " is odd (4:2:2 pairs pixels)");
    }
    if (Status s = check_layout("YUYV", data.size(), width, height, bytes_per_line, 2); !s) return s;
    resize(out, width, height);
    const YcbcrToRgb convert(encoding);
    const auto w = static_cast<std::size_t>(width);
    for (int y = 0; y < height; ++y) {
        const std::uint8_t* src = data.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(bytes_per_line);
        std::uint8_t* dst = out.pixels.data() + static_cast<std::size_t>(y) * w * 3;
        for (std::size_t x = 0; x < w; x += 2) {
            const std::uint8_t* pair = src + 2 * x;  // Y0 Cb Y1 Cr
            convert(pair[0], pair[1], pair[3], dst + 3 * x);
            convert(pair[2], pair[1], pair[3], dst + 3 * x + 3);
        }
    }
    return {};
}

Status convert_yuv420(CaptureFormat format, std::span<const PlaneBytes> planes, int width, int height,
                      YcbcrEncoding encoding, GrayImage& grey, Rgb8Image* colour) {
    if (!is_yuv420(format)) return make_error(EINVAL, pixel_format_name(format) + " is not a 4:2:0 format");
    if (planes.empty()) return make_error(EINVAL, pixel_format_name(format) + " buffer: no planes");
    auto view = yuv420_view(format, planes, width, height);
    if (!view) return view.error();
    if (Status s = grey_from_grey(view->y.data, width, height, view->y.bytes_per_line, grey); !s) return s;
    if (colour == nullptr) return {};
    resize(*colour, width, height);
    const YcbcrToRgb convert(encoding);
    const auto w = static_cast<std::size_t>(width);
    const auto step = static_cast<std::size_t>(view->chroma_step);
    for (int y = 0; y < height; ++y) {
        const std::uint8_t* luma = grey.pixels.data() + static_cast<std::size_t>(y) * w;
        const std::size_t crow =
            static_cast<std::size_t>(y / 2) * static_cast<std::size_t>(view->chroma_bytes_per_line);
        const std::uint8_t* cb = view->cb.data() + crow;
        const std::uint8_t* cr = view->cr.data() + crow;
        std::uint8_t* dst = colour->pixels.data() + static_cast<std::size_t>(y) * w * 3;
        for (std::size_t x = 0; x < w; ++x) convert(luma[x], cb[(x / 2) * step], cr[(x / 2) * step], dst + 3 * x);
    }
    return {};
}

void rgb_from_grey(const GrayImage& grey, Rgb8Image& out) {
    resize(out, grey.width, grey.height);
    for (std::size_t i = 0; i < grey.pixels.size(); ++i) {
        std::fill_n(out.pixels.data() + 3 * i, 3, grey.pixels[i]);
    }
}

Status convert_rgb24(CaptureFormat format, std::span<const std::uint8_t> data, int width, int height,
                     int bytes_per_line, GrayImage& grey, Rgb8Image* colour) {
    if (format != CaptureFormat::rgb24 && format != CaptureFormat::bgr24) {
        return make_error(EINVAL, "convert_rgb24: " + pixel_format_name(format) + " is not RGB3 or BGR3");
    }
    const char* name = format == CaptureFormat::rgb24 ? "RGB3" : "BGR3";
    if (Status s = check_layout(name, data.size(), width, height, bytes_per_line, 3); !s) return s;
    resize(grey, width, height);
    if (colour != nullptr) resize(*colour, width, height);
    const int r = format == CaptureFormat::rgb24 ? 0 : 2;  // byte offset of R' in a pixel
    const int b = 2 - r;
    for (int y = 0; y < height; ++y) {
        const std::uint8_t* row = data.data() + static_cast<std::ptrdiff_t>(y) * bytes_per_line;
        const std::size_t first = static_cast<std::size_t>(y) * static_cast<std::size_t>(width);
        for (int x = 0; x < width; ++x) {
            const std::uint8_t* p = row + 3 * x;
            // 0.299, 0.587, 0.114 in 16.16 fixed point (sum 65536), as grey_from_rgb.
            grey.pixels[first + static_cast<std::size_t>(x)] =
                static_cast<std::uint8_t>((19595 * p[r] + 38470 * p[1] + 7471 * p[b] + 32768) >> 16);
            if (colour == nullptr) continue;
            std::uint8_t* out = colour->pixels.data() + 3 * (first + static_cast<std::size_t>(x));
            out[0] = p[r];
            out[1] = p[1];
            out[2] = p[b];
        }
    }
    return {};
}

void grey_from_rgb(const Rgb8Image& rgb, GrayImage& out) {
    resize(out, rgb.size.width, rgb.size.height);
    for (std::size_t i = 0; i < out.pixels.size(); ++i) {
        const std::uint8_t* p = rgb.pixels.data() + 3 * i;
        // 0.299, 0.587, 0.114 in 16.16 fixed point (sum 65536).
        out.pixels[i] = static_cast<std::uint8_t>((19595 * p[0] + 38470 * p[1] + 7471 * p[2] + 32768) >> 16);
    }
}

}  // namespace mogao
