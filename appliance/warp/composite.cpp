// SPDX-License-Identifier: Apache-2.0
#include "appliance/warp/composite.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "appliance/warp/calibration_validation.h"
#include "appliance/warp/inverse_warp.h"
#include "appliance/warp/response_curve.h"
#include "appliance/warp/warp_sampling.h"

namespace mogao {
namespace {

void require_image(const RgbFloatImage& image, const std::string& what) {
    validate_size(image.size, what);
    if (image.pixels.size() != static_cast<std::size_t>(image.size.pixel_count()) * 3) {
        throw std::invalid_argument(what + ": " + std::to_string(image.pixels.size()) + " values, width*height*3 = " +
                                    std::to_string(image.size.pixel_count() * 3) + " expected");
    }
}

// The indirect light field of render_output: sized like its values, finite and >= 0 (negative
// light would add to the content instead of taking the screen's own light off it).
void require_indirect(const RgbFloatImage& field) {
    const std::string what = "render_output: indirect light field";
    require_image(field, what);
    const auto bad =
        std::find_if(field.pixels.begin(), field.pixels.end(), [](float v) { return !std::isfinite(v) || v < 0.0F; });
    if (bad == field.pixels.end()) return;
    const auto i = static_cast<std::size_t>(bad - field.pixels.begin());
    const auto texel = static_cast<int>(i / 3);
    throw std::invalid_argument(
        what + ": value " + std::to_string(*bad) + " at (" + std::to_string(texel % field.size.width) + ", " +
        std::to_string(texel / field.size.width) + ") channel " + std::to_string(i % 3) + ", must be finite and >= 0");
}

// Bilinear, clamp-to-edge, at pixel-index coordinates (pixel i's centre is i).
std::array<float, 3> bilinear(const RgbFloatImage& image, double px, double py) {
    const double x = std::clamp(px, 0.0, static_cast<double>(image.size.width - 1));
    const double y = std::clamp(py, 0.0, static_cast<double>(image.size.height - 1));
    const int x0 = static_cast<int>(x);
    const int y0 = static_cast<int>(y);
    const int x1 = std::min(x0 + 1, image.size.width - 1);
    const int y1 = std::min(y0 + 1, image.size.height - 1);
    const double fx = x - x0;
    const double fy = y - y0;
    std::array<float, 3> out{};
    const float* p00 = image.at(x0, y0);
    const float* p10 = image.at(x1, y0);
    const float* p01 = image.at(x0, y1);
    const float* p11 = image.at(x1, y1);
    for (std::size_t c = 0; c < 3; ++c) {
        const double top = p00[c] + (static_cast<double>(p10[c]) - p00[c]) * fx;
        const double bottom = p01[c] + (static_cast<double>(p11[c]) - p01[c]) * fx;
        out[c] = static_cast<float>(top + (bottom - top) * fy);
    }
    return out;
}

}  // namespace

std::array<float, 3> sample_content(const RgbFloatImage& content, double u, double v) {
    if (std::isnan(u) || std::isnan(v)) return {0.0F, 0.0F, 0.0F};
    return bilinear(content, u * content.size.width - 0.5, v * content.size.height - 0.5);
}

std::array<float, 3> take_off_indirect_light(std::array<float, 3> linear, const RgbFloatImage& indirect, double u,
                                             double v) {
    if (indirect.pixels.empty()) return linear;
    const std::array<float, 3> screen_light = sample_content(indirect, u, v);
    for (std::size_t c = 0; c < 3; ++c) linear[c] = std::max(linear[c] - screen_light[c], 0.0F);
    return linear;
}

RgbFloatImage render_output(const ProjectorCalibration& projector, const RgbFloatImage& content_linear,
                            const RgbFloatImage& indirect) {
    validate_projector(projector, "render_output: projector '" + projector.id + "'");
    require_image(content_linear, "render_output: content");
    const bool has_indirect = !(indirect.size == ImageSize{} && indirect.pixels.empty());
    if (has_indirect) require_indirect(indirect);
    RgbFloatImage out(projector.output, 0.0F);
    for (int y = 0; y < projector.output.height; ++y) {
        for (int x = 0; x < projector.output.width; ++x) {
            const ContentUv uv = sample_warp(projector.warp, projector.output, x, y);
            if (!uv.valid()) continue;  // no content: signal 0
            // At the screen point uv itself: the field lives in the calibration's content
            // coordinates, as the warp does.
            const std::array<float, 3> rgb =
                take_off_indirect_light(sample_content(content_linear, uv.u, uv.v), indirect, uv.u, uv.v);
            const float weight = sample_blend(projector.blend, projector.output, x, y);
            const std::array<float, 3> beta = sample_beta(projector.beta, projector.output, x, y);
            float* dst = out.at(x, y);
            for (std::size_t c = 0; c < 3; ++c) {
                dst[c] = apply_response(projector.response, static_cast<int>(c), rgb[c] * weight + beta[c]);
            }
        }
    }
    return out;
}

RgbFloatImage composite_on_screen(const ScreenCalibration& screen, const std::vector<RgbFloatImage>& outputs) {
    validate_screen(screen);
    if (outputs.size() != screen.projectors.size()) {
        throw std::invalid_argument("composite_on_screen: " + std::to_string(outputs.size()) + " outputs for " +
                                    std::to_string(screen.projectors.size()) + " projectors");
    }
    RgbFloatImage light_sum(screen.content, 0.0F);
    for (std::size_t k = 0; k < outputs.size(); ++k) {
        const ProjectorCalibration& p = screen.projectors[k];
        const std::string who = "composite_on_screen: outputs[" + std::to_string(k) + "]";
        require_image(outputs[k], who);
        if (!(outputs[k].size == p.output)) {
            throw std::invalid_argument(who + ": size differs from projector '" + p.id + "' output");
        }
        // Undo the response once per output pixel: projector light = response^-1(signal).
        RgbFloatImage light(p.output);
        for (std::size_t i = 0; i < light.pixels.size(); ++i) {
            light.pixels[i] = invert_response(p.response, static_cast<int>(i % 3), outputs[k].pixels[i]);
        }
        const InverseWarp inv = build_inverse_warp(p.warp, p.output, screen.content);
        for (int j = 0; j < screen.content.height; ++j) {
            for (int i = 0; i < screen.content.width; ++i) {
                const std::size_t idx = light_sum.index(i, j) / 3 * 2;
                const float ox = inv.xy[idx];
                const float oy = inv.xy[idx + 1];
                if (std::isnan(ox)) continue;
                const std::array<float, 3> rgb = bilinear(light, ox, oy);
                float* dst = light_sum.at(i, j);
                for (std::size_t c = 0; c < 3; ++c) dst[c] += rgb[c];
            }
        }
    }
    return light_sum;
}

}  // namespace mogao
