// SPDX-License-Identifier: Apache-2.0
// Projector response curves: construction, application, inversion and validation of the
// ResponseCurve LUT of projector_calibration.h.
//
// A ResponseCurve maps linear light in [0, 1] to the projector's input signal in [0, 1]
// (signal = lut(linear)). Each channel's table has n >= 2 samples; sample k sits at linear
// k / (n - 1) and the table is piecewise linear between samples. The gamma default follows the
// usual display model signal = linear^(1/gamma) with gamma 2.2 (the "gamma 2.2" of IEC 61966-2-1's
// sRGB reference display, without sRGB's linear toe).
//
// Errors: bad arguments throw std::invalid_argument naming the parameter and its limit.
#pragma once

#include <string_view>
#include <vector>

#include "common/projector_calibration.h"

namespace mogao {

inline constexpr int kDefaultResponseEntries = 4096;
inline constexpr int kMaxResponseEntries = 1 << 20;  // 4 MiB per channel: far above any real LUT

// signal = (k / (entries - 1))^(1 / gamma) in all three channels. gamma in (0, 10],
// entries in [2, kMaxResponseEntries].
[[nodiscard]] ResponseCurve make_gamma_response(double gamma = 2.2, int entries = kDefaultResponseEntries);

// Throws std::invalid_argument (message starts with `what`) unless every channel has the same
// length in [2, kMaxResponseEntries], every value is finite, in [0, 1] and non-decreasing.
void validate_response(const ResponseCurve& curve, std::string_view what = "response");

// signal = lut(linear), linear clamped to [0, 1] first (NaN counts as 0: no light). channel 0..2.
// Preconditions (not re-checked per call, for speed): validate_response passed.
[[nodiscard]] float apply_response(const ResponseCurve& curve, int channel, float linear);

// The monotone inverse: the smallest linear x in [0, 1] with lut(x) = signal for the piecewise-linear
// table, so apply_response(invert_response(s)) = s for s in [lut[0], lut[n-1]]; signals below
// lut[0] give 0 and above lut[n-1] give 1 (NaN gives 0). Flat runs of the table (several linear
// values with the same signal) resolve to their lowest linear value.
[[nodiscard]] float invert_response(const ResponseCurve& curve, int channel, float signal);

// The same two operations on one channel's table.
[[nodiscard]] double apply_lut(const std::vector<float>& lut, double linear);
[[nodiscard]] double invert_lut(const std::vector<float>& lut, double signal);

}  // namespace mogao
