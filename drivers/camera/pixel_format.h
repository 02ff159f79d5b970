// SPDX-License-Identifier: Apache-2.0
// Conversions from the V4L2 / libcamera wire formats the capture accepts to GrayImage and to
// R'G'B' (Rgb8Image), and their names. Pure functions.
//
// Layouts (V4L2 uAPI, "Image Formats"; rows are `bytes_per_line` apart, the last row may be short):
//   GREY   one byte per pixel, Y' 0..255
//   YUYV   4:2:2 packed, Y0 Cb0 Y1 Cr0 per two pixels (width even)
//   NV12   4:2:0 semi-planar: the Y' plane, then one plane of interleaved Cb Cr (NV21: Cr Cb), each
//          chroma sample covering 2x2 pixels; chroma rows have the luma's bytes_per_line
//   YU12   4:2:0 planar ("YUV420"): Y', then Cb, then Cr (YV12 / "YVU420": Cr before Cb); chroma
//          rows are bytes_per_line / 2 apart
//   NV12M, NV21M, YUV420M, YVU420M: the same planes in separate buffers, each with its own
//          bytes_per_line (V4L2_BUF_TYPE_VIDEO_CAPTURE_MPLANE)
//   RGB3   packed R'G'B', bytes R G B per pixel (BGR3: B G R)
//   MJPEG  see mjpeg_decoder.h
// Odd sizes: a 4:2:0 chroma plane has ceil(width / 2) x ceil(height / 2) samples.
//
// Grey is the Y' bytes as they are (limited-range Y' 16..235 is not expanded: AprilTag thresholds
// locally, so a range scale changes nothing it measures).
//
// Colour: R'G'B' from Y'CbCr with the matrix and quantization of the frame's V4L2 fields
// (ycbcr_enc, quantization, colorspace; ycbcr_encoding_from_v4l2). The matrices are those of
// ITU-R BT.601-7 (Kr 0.299, Kb 0.114), BT.709-6 (Kr 0.2126, Kb 0.0722), BT.2020-2 (Kr 0.2627,
// Kb 0.0593) and SMPTE 240M (Kr 0.212, Kb 0.087): R' = Y' + 2(1-Kr) Cr, B' = Y' + 2(1-Kb) Cb,
// G' = (Y' - Kr R' - Kb B') / (1 - Kr - Kb), with Y' in [0, 1] and Cb, Cr in [-0.5, 0.5];
// limited range ("studio swing", BT.601 / BT.709 8-bit coding) maps Y' 16..235 and C 16..240 onto
// those, full range (JFIF, ITU-T T.871) Y' 0..255 and C 0..255 around 128. Results are rounded and
// clamped to 0..255. Chroma is not interpolated (each sample covers its 2x2 or 2x1 pixels).
//
// Errors (common/result.h): EINVAL for a width/height outside [1, kMaxCaptureDimension], a
// stride below the row size, or a buffer shorter than the image it must hold; the message names
// the format, the plane, the value and the limit.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "common/image.h"
#include "common/result.h"
#include "drivers/camera/camera_frame.h"

namespace mogao {

// Largest width or height accepted from a driver or file: far above any tracking camera, small
// enough that a corrupt header cannot make the appliance allocate gigabytes.
inline constexpr int kMaxCaptureDimension = 8192;

// "GREY", "YUYV", "MJPG", "file", "NV12", "NV21", "YU12", "YV12", "RGB3", "BGR3" (the V4L2 fourccs).
[[nodiscard]] std::string pixel_format_name(CaptureFormat format);

// A V4L2 fourcc as four characters ("YUYV"); non-printable bytes become '?'.
[[nodiscard]] std::string fourcc_name(std::uint32_t fourcc);

// True for the 4:2:0 formats (nv12, nv21, yuv420, yvu420).
[[nodiscard]] bool is_yuv420(CaptureFormat format);

// The Y'CbCr matrix and quantization of a frame.
enum class YcbcrMatrix { bt601, bt709, bt2020, smpte240m };
enum class YcbcrRange { limited, full };
struct YcbcrEncoding {
    YcbcrMatrix matrix = YcbcrMatrix::bt601;
    YcbcrRange range = YcbcrRange::limited;
    friend bool operator==(const YcbcrEncoding&, const YcbcrEncoding&) = default;
};

// From V4L2's v4l2_pix_format(_mplane) fields, with the defaults of the V4L2 uAPI ("Colorspaces",
// V4L2_MAP_YCBCR_ENC_DEFAULT / V4L2_MAP_QUANTIZATION_DEFAULT): ycbcr_enc DEFAULT follows the
// colorspace (REC709 -> BT.709, BT2020 -> BT.2020, SMPTE240M -> 240M, else BT.601); quantization
// DEFAULT is full range for the JPEG colorspace, limited otherwise. XV601/XV709 use the
// BT.601/BT.709 matrices (their extended gamut is clamped).
[[nodiscard]] YcbcrEncoding ycbcr_encoding_from_v4l2(std::uint32_t colorspace, std::uint32_t ycbcr_enc,
                                                     std::uint32_t quantization);
[[nodiscard]] std::string ycbcr_encoding_name(YcbcrEncoding encoding);  // "BT.601 limited"

// One Y'CbCr sample to R'G'B' (rgb[0..2]), per the formulas above.
void rgb_from_ycbcr(std::uint8_t y, std::uint8_t cb, std::uint8_t cr, YcbcrEncoding encoding, std::uint8_t* rgb);

// One plane of a frame as the driver delivered it.
struct PlaneBytes {
    std::span<const std::uint8_t> data;
    int bytes_per_line = 0;
};

// Copies a GREY buffer into `out` (resized to width x height).
[[nodiscard]] Status grey_from_grey(std::span<const std::uint8_t> data, int width, int height, int bytes_per_line,
                                    GrayImage& out);

// Extracts Y' from a YUYV buffer into `out` (resized to width x height). Width must be even.
[[nodiscard]] Status grey_from_yuyv(std::span<const std::uint8_t> data, int width, int height, int bytes_per_line,
                                    GrayImage& out);

// YUYV to R'G'B' (resized to width x height). Width must be even.
[[nodiscard]] Status rgb_from_yuyv(std::span<const std::uint8_t> data, int width, int height, int bytes_per_line,
                                   YcbcrEncoding encoding, Rgb8Image& out);

// A 4:2:0 frame (format nv12, nv21, yuv420 or yvu420) from one plane (NV12, NV21, YU12, YV12: the
// chroma follows the luma in the same buffer) or from its separate planes (2 for NV12M/NV21M, 3 for
// YUV420M/YVU420M). Y' into `grey`; with `colour` non-null, also R'G'B' into *colour.
[[nodiscard]] Status convert_yuv420(CaptureFormat format, std::span<const PlaneBytes> planes, int width, int height,
                                    YcbcrEncoding encoding, GrayImage& grey, Rgb8Image* colour);

// A packed 24-bit frame (format rgb24 or bgr24): the BT.601 luma (as grey_from_rgb) into `grey`;
// with `colour` non-null, also the R'G'B' (in R G B order) into *colour.
[[nodiscard]] Status convert_rgb24(CaptureFormat format, std::span<const std::uint8_t> data, int width, int height,
                                   int bytes_per_line, GrayImage& grey, Rgb8Image* colour);

// GREY to R'G'B' (R' = G' = B' = Y').
void rgb_from_grey(const GrayImage& grey, Rgb8Image& out);

// The BT.601 luma of R'G'B' (Y' = 0.299 R' + 0.587 G' + 0.114 B', rounded; JFIF / ITU-T T.871).
void grey_from_rgb(const Rgb8Image& rgb, GrayImage& out);

}  // namespace mogao
