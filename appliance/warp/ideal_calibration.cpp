// SPDX-License-Identifier: Apache-2.0
#include "appliance/warp/ideal_calibration.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "appliance/warp/calibration_validation.h"

namespace mogao {

std::vector<ContentBand> ideal_bands(int projectors, double overlap) {
    if (projectors < 1 || projectors > kMaxProjectors) {
        throw std::invalid_argument("ideal calibration: projectors " + std::to_string(projectors) + " is outside [1, " +
                                    std::to_string(kMaxProjectors) + "]");
    }
    // Below 0.5 only neighbours overlap, and a projector's left and right ramps never meet.
    if (!(overlap >= 0.0 && overlap < 0.5)) {
        throw std::invalid_argument("ideal calibration: overlap " + std::to_string(overlap) + " is outside [0, 0.5)");
    }
    const double band = 1.0 / (projectors - (projectors - 1) * overlap);
    const double shared = band * overlap;
    std::vector<ContentBand> bands(static_cast<std::size_t>(projectors));
    for (int k = 0; k < projectors; ++k) bands[static_cast<std::size_t>(k)].u0 = k * band * (1.0 - overlap);
    // Each band ends exactly `shared` past its neighbour's start (no rounding gap between bands,
    // identical edges for both projectors of an overlap), and the last one exactly at 1.
    for (std::size_t k = 0; k + 1 < bands.size(); ++k) bands[k].u1 = bands[k + 1].u0 + shared;
    bands.back().u1 = 1.0;
    return bands;
}

double smooth_ramp(double t) {
    const double x = std::clamp(t, 0.0, 1.0);
    return x * x * (3.0 - 2.0 * x);
}

double ideal_blend_weight(const std::vector<ContentBand>& bands, int k, double u) {
    if (k < 0 || static_cast<std::size_t>(k) >= bands.size()) {
        throw std::invalid_argument("ideal_blend_weight: projector " + std::to_string(k) + " is outside [0, " +
                                    std::to_string(bands.size()) + ")");
    }
    const auto i = static_cast<std::size_t>(k);
    const ContentBand& b = bands[i];
    if (u < b.u0 || u > b.u1) return 0.0;
    // Left overlap with k - 1: [b.u0, bands[k-1].u1], the same t that projector k - 1 uses.
    if (i > 0 && u < bands[i - 1].u1) return smooth_ramp((u - b.u0) / (bands[i - 1].u1 - b.u0));
    // Right overlap with k + 1: [bands[k+1].u0, b.u1]. Without overlap the shared edge belongs to
    // k + 1 (bands are then half-open), so the weights still sum to 1 there.
    if (i + 1 < bands.size() && u >= bands[i + 1].u0) {
        const double width = b.u1 - bands[i + 1].u0;
        return width > 0.0 ? 1.0 - smooth_ramp((u - bands[i + 1].u0) / width) : 0.0;
    }
    return 1.0;
}

ScreenCalibration make_ideal_calibration(const IdealCalibrationParams& params) {
    const std::vector<ContentBand> bands = ideal_bands(params.projectors, params.overlap);
    validate_size(params.output, "ideal calibration: output");
    validate_size(params.content, "ideal calibration: content");
    const ResponseCurve response = make_gamma_response(params.gamma, params.response_entries);

    ScreenCalibration screen;
    screen.content = params.content;
    const ImageSize out = params.output;
    const auto count = static_cast<std::size_t>(out.pixel_count());
    for (int k = 0; k < params.projectors; ++k) {
        const ContentBand& band = bands[static_cast<std::size_t>(k)];
        ProjectorCalibration p;
        p.id = "proj" + std::to_string(k);
        p.output = out;
        p.warp.size = out;
        p.warp.uv.resize(count * 2);
        p.blend.size = out;
        p.blend.weight.resize(count);
        p.response = response;
        // Weights depend on u only: one row, copied down.
        std::vector<float> row_u(static_cast<std::size_t>(out.width));
        std::vector<float> row_w(static_cast<std::size_t>(out.width));
        for (int x = 0; x < out.width; ++x) {
            const double u = band.u0 + (band.u1 - band.u0) * (x + 0.5) / out.width;
            row_u[static_cast<std::size_t>(x)] = static_cast<float>(u);
            row_w[static_cast<std::size_t>(x)] = static_cast<float>(ideal_blend_weight(bands, k, u));
        }
        for (int y = 0; y < out.height; ++y) {
            const auto v = static_cast<float>((y + 0.5) / out.height);
            for (int x = 0; x < out.width; ++x) {
                const std::size_t i =
                    static_cast<std::size_t>(y) * static_cast<std::size_t>(out.width) + static_cast<std::size_t>(x);
                p.warp.uv[2 * i] = row_u[static_cast<std::size_t>(x)];
                p.warp.uv[2 * i + 1] = v;
                p.blend.weight[i] = row_w[static_cast<std::size_t>(x)];
            }
        }
        screen.projectors.push_back(std::move(p));
    }
    return screen;
}

}  // namespace mogao
