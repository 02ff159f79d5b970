// SPDX-License-Identifier: Apache-2.0
// Lossless frame files: PNG (libpng simplified API) and binary PPM (P6).
//
// The farm writes PPM for lossless test frames (trivial format, no library, easy to diff) and PNG
// for anything a person will open. Writes are atomic (write_file_atomically): a reader sees the old
// file or the whole new one. All readers refuse images above kMaxDecodedDimension per side.
#pragma once

#include <filesystem>

#include "common/codec_errors.h"
#include "common/image.h"

namespace mogao {

// How hard write_png compresses. `fast` is libpng's PNG_IMAGE_FLAG_FAST (no row filters, zlib
// level 3): several times faster than `small` (libpng's default), for a file about twice as large
// on a rendered frame. For previews written while something else needs the CPU (a kiosk's output
// PNGs beside the farm and the rasteriser).
enum class PngCompression { small, fast };

// 8-bit RGB PNG with an sRGB chunk. Throws std::invalid_argument for an inconsistent image and
// EncodeError naming `path` and the reason if libpng fails or the file cannot be written (missing
// directory, permissions, full disk).
void write_png(const std::filesystem::path& path, const Rgb8Image& image,
               PngCompression compression = PngCompression::small);

// Any PNG libpng can read, converted to RGB8: grayscale is replicated to R=G=B, palettes are
// expanded, alpha is composited over black, 16-bit samples are reduced to 8 bits, and a file whose
// gAMA/cHRM chunks say it is not sRGB is converted to sRGB (8-bit files without them are taken as
// sRGB, unchanged). Throws DecodeError naming `path` and the reason (libpng's message, or errno's
// if the file cannot be read).
[[nodiscard]] Rgb8Image read_png(const std::filesystem::path& path);

// Binary PPM: "P6\n<width> <height>\n255\n" then the raw RGB bytes. Errors as write_png.
void write_ppm(const std::filesystem::path& path, const Rgb8Image& image);

// Binary PPM (P6) with maxval 255; '#' comments in the header are allowed. Other maxvals, ASCII
// P3, truncated data and unreadable files are refused with a DecodeError naming `path`.
[[nodiscard]] Rgb8Image read_ppm(const std::filesystem::path& path);

}  // namespace mogao
