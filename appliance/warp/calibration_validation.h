// SPDX-License-Identifier: Apache-2.0
// Checks of the calibration value types (projector_calibration.h) that every consumer runs before
// trusting one: the CPU compositor, the MPCDI writer and the GL backend.
//
// Errors: std::invalid_argument whose message starts with `what` (e.g. "projectors[1] 'proj1'"),
// names the field, the offending index and the limit. Nothing is repaired silently.
#pragma once

#include <string_view>

#include "common/projector_calibration.h"

namespace mogao {

// Largest width or height of an output, a content frame or a grid (same bound as the farm's
// decoders: 16384^2 samples is far above any projector and keeps allocations bounded).
inline constexpr int kMaxCalibrationDimension = 16384;

// size in [1, kMaxCalibrationDimension] per side.
void validate_size(ImageSize size, std::string_view what);

// size valid; uv holds width*height*2 values; every (u, v) pair is both finite or both NaN
// ("no content"). Values outside [0, 1] are allowed (a warp may aim past the content edge; the
// sampler clamps) but must be finite.
void validate_warp(const WarpMap& warp, std::string_view what);

// size valid; weight holds width*height values, each finite and in [0, 1].
void validate_blend(const BlendMask& blend, std::string_view what);

// Either empty (size 0 x 0, no values) or: size valid; rgb holds width*height*3 values, each finite
// and in [0, 1].
void validate_beta(const BlackOffset& beta, std::string_view what);

// id non-empty; output size valid; warp and blend valid and not larger than the output (a grid
// finer than the output has no sample-to-pixel meaning); response valid (validate_response).
void validate_projector(const ProjectorCalibration& projector, std::string_view what);

// content size valid; 1..64 projectors, each valid, ids unique.
void validate_screen(const ScreenCalibration& screen);

inline constexpr int kMaxProjectors = 64;

}  // namespace mogao
