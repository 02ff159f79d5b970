// SPDX-License-Identifier: Apache-2.0
// PatternDisplay: calibration patterns shown on the appliance's own outputs (drivers/output.h: the
// KMS backend on site, the headless one in tests), each output receiving exactly the pattern's
// value as its signal.
//
// Exactness: the outputs draw through the kiosk's WarpBlendRenderer with an identity calibration:
// warp = output pixel centre / output size over a content frame of the output's size (so content
// texel x is read at its centre), blend 1, no beta, and a response LUT that is the sRGB encoding
// (IEC 61966-2-1, sec. 5.2) sampled at kIdentityLutEntries points. The shader decodes each sRGB
// content texel to linear light and the LUT encodes it again, so the 8-bit output code equals the
// content code (the piecewise-linear LUT is within 0.005 codes of the encoding; the test shows every
// code 0..255 and reads it back). A pattern value s in [0, 1] becomes code round(255 s): the signal
// is quantised to the outputs' 8 bits, as the kiosk's own pictures are.
//
// Timing: show() stages every output whose picture changes (black where no projector's pattern
// goes; an output already showing its pattern is left as it is, which saves most draws: the Gray
// code changes one projector at a time) and commits them in one round (one atomic commit on KMS),
// then waits until every output's flip completed (KMS flip events on the DRM fd; headless
// completes on commit). Errors: common/result.h; ETIMEDOUT naming
// the output when a flip does not complete within the timeout.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "common/image.h"
#include "common/projector_calibration.h"
#include "common/result.h"
#include "drivers/output.h"

namespace mogao::calibrate {

inline constexpr int kIdentityLutEntries = 4096;

// The calibration that shows its content unchanged on an output of `output` pixels (above).
[[nodiscard]] ProjectorCalibration identity_calibration(ImageSize output);

// The content frame whose display gives the signal round(255 * clamp(s, 0, 1)) per pixel and
// channel: `signal` CV_32FC1 (grey: R = G = B) or CV_32FC3 (R, G, B) of `size`, or empty (black).
// Throws std::invalid_argument naming the expected size and types otherwise.
[[nodiscard]] Rgb8Image pattern_content(const cv::Mat& signal, ImageSize size);

class PatternDisplay {
public:
    // Adds one identity projector per output of `backend` to its renderer (the backend's GL context
    // must be current: it is after create). `backend` must outlive the display.
    [[nodiscard]] static Result<PatternDisplay> create(OutputBackend& backend, int flip_timeout_ms = 2000);

    [[nodiscard]] std::size_t output_count() const { return backend_->outputs().size(); }
    [[nodiscard]] const OutputInfo& output(std::size_t i) const { return backend_->outputs().at(i); }

    // Shows per_output[i] (pattern_content's signal, empty = black) on output i, every output in one
    // round, and returns once every flip completed. EINVAL for a count other than output_count() or
    // a signal of the wrong size or type.
    [[nodiscard]] Status show_outputs(const std::vector<cv::Mat>& per_output);

private:
    PatternDisplay(OutputBackend& backend, std::vector<std::size_t> renderer_index, int flip_timeout_ms)
        : backend_(&backend), renderer_index_(std::move(renderer_index)), flip_timeout_ms_(flip_timeout_ms) {}
    [[nodiscard]] Status wait_for_flips();

    OutputBackend* backend_;
    std::vector<std::size_t> renderer_index_;  // per output: its identity projector in the renderer
    int flip_timeout_ms_;
    std::vector<std::optional<Rgb8Image>> shown_;  // per output: what it shows (nullopt: not drawn yet)
};

}  // namespace mogao::calibrate
