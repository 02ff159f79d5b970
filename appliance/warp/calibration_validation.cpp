// SPDX-License-Identifier: Apache-2.0
#include "appliance/warp/calibration_validation.h"

#include <cmath>
#include <set>
#include <stdexcept>
#include <string>

#include "appliance/warp/response_curve.h"

namespace mogao {
namespace {

std::string size_text(ImageSize s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

std::string pixel_text(std::size_t index, int width) {
    const auto w = static_cast<std::size_t>(width);
    return "(" + std::to_string(index % w) + ", " + std::to_string(index / w) + ")";
}

}  // namespace

void validate_size(ImageSize size, std::string_view what) {
    if (size.width < 1 || size.height < 1 || size.width > kMaxCalibrationDimension ||
        size.height > kMaxCalibrationDimension) {
        throw std::invalid_argument(std::string(what) + ": size " + size_text(size) + " is outside 1.." +
                                    std::to_string(kMaxCalibrationDimension) + " per side");
    }
}

void validate_warp(const WarpMap& warp, std::string_view what) {
    const std::string who = std::string(what) + ".warp";
    validate_size(warp.size, who);
    const auto count = static_cast<std::size_t>(warp.size.pixel_count());
    if (warp.uv.size() != count * 2) {
        throw std::invalid_argument(who + ": uv holds " + std::to_string(warp.uv.size()) + " values, " +
                                    size_text(warp.size) + " x 2 = " + std::to_string(count * 2) + " expected");
    }
    for (std::size_t i = 0; i < count; ++i) {
        const float u = warp.uv[2 * i];
        const float v = warp.uv[2 * i + 1];
        const bool both_nan = std::isnan(u) && std::isnan(v);
        if (!both_nan && !(std::isfinite(u) && std::isfinite(v))) {
            throw std::invalid_argument(who + ": sample " + pixel_text(i, warp.size.width) + " = (" +
                                        std::to_string(u) + ", " + std::to_string(v) +
                                        ") must be finite or NaN in both u and v");
        }
    }
}

void validate_blend(const BlendMask& blend, std::string_view what) {
    const std::string who = std::string(what) + ".blend";
    validate_size(blend.size, who);
    const auto count = static_cast<std::size_t>(blend.size.pixel_count());
    if (blend.weight.size() != count) {
        throw std::invalid_argument(who + ": weight holds " + std::to_string(blend.weight.size()) + " values, " +
                                    size_text(blend.size) + " = " + std::to_string(count) + " expected");
    }
    for (std::size_t i = 0; i < count; ++i) {
        const float w = blend.weight[i];
        if (!(w >= 0.0F && w <= 1.0F)) {
            throw std::invalid_argument(who + ": weight " + pixel_text(i, blend.size.width) + " = " +
                                        std::to_string(w) + " is outside [0, 1] (or not finite)");
        }
    }
}

void validate_beta(const BlackOffset& beta, std::string_view what) {
    const std::string who = std::string(what) + ".beta";
    if (beta.size.width == 0 && beta.size.height == 0 && beta.rgb.empty()) return;
    validate_size(beta.size, who);
    const auto count = static_cast<std::size_t>(beta.size.pixel_count()) * 3;
    if (beta.rgb.size() != count) {
        throw std::invalid_argument(who + ": rgb holds " + std::to_string(beta.rgb.size()) + " values, " +
                                    size_text(beta.size) + " x 3 = " + std::to_string(count) + " expected");
    }
    for (std::size_t i = 0; i < count; ++i) {
        const float b = beta.rgb[i];
        if (!(b >= 0.0F && b <= 1.0F)) {
            throw std::invalid_argument(who + ": offset " + pixel_text(i / 3, beta.size.width) + " channel " +
                                        std::to_string(i % 3) + " = " + std::to_string(b) +
                                        " is outside [0, 1] (or not finite)");
        }
    }
}

void validate_projector(const ProjectorCalibration& projector, std::string_view what) {
    const std::string who(what);
    if (projector.id.empty()) throw std::invalid_argument(who + ": id is empty");
    validate_size(projector.output, who + ".output");
    validate_warp(projector.warp, who);
    validate_blend(projector.blend, who);
    const auto no_finer = [&](ImageSize grid, const char* field) {
        if (grid.width > projector.output.width || grid.height > projector.output.height) {
            throw std::invalid_argument(who + "." + field + ": grid " + size_text(grid) + " is finer than the output " +
                                        size_text(projector.output));
        }
    };
    no_finer(projector.warp.size, "warp");
    no_finer(projector.blend.size, "blend");
    validate_beta(projector.beta, who);
    no_finer(projector.beta.size, "beta");
    validate_response(projector.response, who + ".response");
}

void validate_screen(const ScreenCalibration& screen) {
    validate_size(screen.content, "screen.content");
    const std::size_t n = screen.projectors.size();
    if (n < 1 || n > static_cast<std::size_t>(kMaxProjectors)) {
        throw std::invalid_argument("screen.projectors: " + std::to_string(n) + " projectors, outside 1.." +
                                    std::to_string(kMaxProjectors));
    }
    std::set<std::string> ids;
    for (std::size_t k = 0; k < n; ++k) {
        const ProjectorCalibration& p = screen.projectors[k];
        const std::string who = "screen.projectors[" + std::to_string(k) + "] '" + p.id + "'";
        validate_projector(p, who);
        if (!ids.insert(p.id).second) throw std::invalid_argument(who + ": id is used by an earlier projector");
    }
}

}  // namespace mogao
