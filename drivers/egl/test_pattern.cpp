// SPDX-License-Identifier: Apache-2.0
#include "drivers/egl/test_pattern.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>

namespace mogao {
namespace {

ResponseCurve sample_response(std::size_t entries, double (*f)(double, double), double param) {
    if (entries < 2) throw std::invalid_argument("response LUT needs entries >= 2");
    ResponseCurve curve;
    for (auto& channel : curve.lut) {
        channel.resize(entries);
        for (std::size_t i = 0; i < entries; ++i) {
            const double x = static_cast<double>(i) / static_cast<double>(entries - 1);
            channel[i] = static_cast<float>(f(x, param));
        }
    }
    return curve;
}

double srgb_encode(double x, double /*unused*/) {
    return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055;
}

double gamma_encode(double x, double gamma) { return std::pow(x, 1.0 / gamma); }

}  // namespace

ResponseCurve srgb_response(std::size_t entries) { return sample_response(entries, &srgb_encode, 0.0); }

ResponseCurve gamma_response(double gamma, std::size_t entries) {
    if (!(gamma > 0.0)) throw std::invalid_argument("gamma_response: gamma must be > 0");
    return sample_response(entries, &gamma_encode, gamma);
}

ProjectorCalibration identity_calibration(std::string id, ImageSize output) {
    if (output.width <= 0 || output.height <= 0) {
        throw std::invalid_argument("identity_calibration: output size must be positive");
    }
    ProjectorCalibration c;
    c.id = std::move(id);
    c.output = output;
    c.warp.size = output;
    c.warp.uv.resize(static_cast<std::size_t>(output.pixel_count()) * 2);
    for (int y = 0; y < output.height; ++y) {
        for (int x = 0; x < output.width; ++x) {
            const std::size_t i =
                (static_cast<std::size_t>(y) * static_cast<std::size_t>(output.width) + static_cast<std::size_t>(x)) *
                2;
            c.warp.uv[i] = static_cast<float>((x + 0.5) / output.width);
            c.warp.uv[i + 1] = static_cast<float>((y + 0.5) / output.height);
        }
    }
    c.blend.size = {1, 1};
    c.blend.weight = {1.0f};
    c.response = srgb_response();
    return c;
}

Rgb8Image make_test_pattern(ImageSize size) {
    if (size.width <= 0 || size.height <= 0) throw std::invalid_argument("make_test_pattern: size must be positive");
    static constexpr std::uint8_t kBars[8][3] = {{255, 255, 255}, {255, 255, 0}, {0, 255, 255}, {0, 255, 0},
                                                 {255, 0, 255},   {255, 0, 0},   {0, 0, 255},   {0, 0, 0}};
    Rgb8Image image(size);
    for (int y = 0; y < size.height; ++y) {
        for (int x = 0; x < size.width; ++x) {
            std::uint8_t* px = image.at(x, y);
            if (y < size.height / 2) {
                const auto& bar = kBars[static_cast<std::size_t>(x) * 8 / static_cast<std::size_t>(size.width)];
                px[0] = bar[0];
                px[1] = bar[1];
                px[2] = bar[2];
            } else {
                const auto grey = static_cast<std::uint8_t>(x * 255 / std::max(1, size.width - 1));
                px[0] = px[1] = px[2] = grey;
            }
            const bool grid = x % 64 == 0 || y % 64 == 0 || x == size.width - 1 || y == size.height - 1;
            if (grid) px[0] = px[1] = px[2] = 255;
            if (x < 16 && y < 16) {
                px[0] = 255;
                px[1] = 0;
                px[2] = 0;
            }
        }
    }
    return image;
}

}  // namespace mogao
