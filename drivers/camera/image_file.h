// SPDX-License-Identifier: Apache-2.0
// Reading one still image file as 8-bit grey, for the replay source and the camera tools.
//
// Formats, recognised by their magic bytes (not the file name):
//   PNG  (libpng's simplified API, any bit depth / colour type; 16-bit samples scaled by 255/65535,
//        colour reduced to BT.601 luma Y = 0.299 R + 0.587 G + 0.114 B on the encoded values, as a
//        JPEG's Y and OpenCV's IMREAD_GRAYSCALE do; alpha composited on black);
//   PGM  binary "P5" (Netpbm pgm(5)), maxval 1..65535, scaled to 0..255 with rounding;
//   JPEG (TurboJPEG, decoded straight to luma; colour JPEGs keep only their Y channel, ITU-T T.871).
// Why not OpenCV's imread: libopencv-imgcodecs406 pulls GDAL, GDCM, OpenEXR... (about 130 more
// Debian packages) into the appliance image for three formats that libpng and libjpeg-turbo,
// already there, decode.
//
// Pixels: row-major, top row first, as GrayImage (camera_frame.h).
// Errors (common/result.h), each naming the file: errno of open/read; EFBIG if the file is larger
// than kMaxImageFileBytes; EBADMSG for an unknown format or corrupt/truncated data; EINVAL if a
// side exceeds kMaxCaptureDimension.
#pragma once

#include <cstdint>
#include <filesystem>

#include "common/result.h"
#include "drivers/camera/camera_frame.h"

namespace mogao {

inline constexpr std::uintmax_t kMaxImageFileBytes = 64u << 20;  // 64 MiB: far above 8192^2 grey PGM

[[nodiscard]] Result<GrayImage> read_gray_image(const std::filesystem::path& path);

}  // namespace mogao
