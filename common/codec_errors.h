// SPDX-License-Identifier: Apache-2.0
// Error types of the encode stage and the layout check every entry point shares.
//
// EncodeError: an image could not be turned into bytes (bad arguments, codec failure).
// DecodeError: bytes could not be turned into an image (corrupt, truncated, unsupported, too large).
// Both derive from std::runtime_error; messages name the file (when there is one) and the reason,
// including file-system failures (missing directory, full disk) of the PNG/PPM readers and writers.
// Bad arguments (quality 0, a malformed Rgb8Image) are std::invalid_argument instead.
#pragma once

#include <stdexcept>
#include <string_view>

#include "common/image.h"

namespace mogao {

struct EncodeError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

struct DecodeError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Largest width or height any decoder here will allocate for. 16384^2 RGB8 is 768 MiB: a bound
// that real frames (at most a few 8K-wide projector canvases) never reach but that stops a hostile
// or corrupt header from making the appliance allocate tens of gigabytes.
inline constexpr int kMaxDecodedDimension = 16384;

// Throws std::invalid_argument (message starts with `who`) unless the image is non-empty and its
// pixel vector holds exactly width * height * 3 values.
void require_valid_image(const Rgb8Image& image, std::string_view who);

}  // namespace mogao
