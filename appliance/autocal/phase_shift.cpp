// SPDX-License-Identifier: Apache-2.0
// Phase-shift patterns, their N-step decoding and the unwrapping by the Gray code (phase_shift.h).
#include "appliance/autocal/phase_shift.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace mogao::autocal {

cv::Mat1f phase_shift_pattern(ImageSize size, bool rows, double period_px, int shifts, int i, double gamma) {
    if (shifts < 3) throw std::invalid_argument("phase_shift_pattern: shifts >= 3, got " + std::to_string(shifts));
    if (i < 0 || i >= shifts) {
        throw std::invalid_argument("phase_shift_pattern: pattern " + std::to_string(i) + " outside 0.." +
                                    std::to_string(shifts - 1));
    }
    if (!(period_px >= 2.0)) throw std::invalid_argument("phase_shift_pattern: period_px >= 2");
    if (!(gamma > 0.0 && gamma <= 10.0)) throw std::invalid_argument("phase_shift_pattern: gamma in (0, 10]");
    const double two_pi = 2.0 * std::numbers::pi;
    const int extent = rows ? size.height : size.width;
    std::vector<float> line(static_cast<std::size_t>(extent));
    for (int x = 0; x < extent; ++x) {
        const double light = 0.5 + 0.5 * std::cos(two_pi * (x + 0.5) / period_px - two_pi * i / shifts);
        line[static_cast<std::size_t>(x)] = static_cast<float>(std::pow(std::clamp(light, 0.0, 1.0), 1.0 / gamma));
    }
    cv::Mat1f img(size.height, size.width);
    for (int y = 0; y < size.height; ++y) {
        for (int x = 0; x < size.width; ++x) img(y, x) = line[static_cast<std::size_t>(rows ? y : x)];
    }
    return img;
}

PhaseImage decode_phase(const std::vector<cv::Mat1f>& images, double period_px) {
    const int n = static_cast<int>(images.size());
    if (n < 3) throw std::invalid_argument("decode_phase: >= 3 images, got " + std::to_string(n));
    for (const cv::Mat1f& m : images) {
        if (m.size() != images[0].size()) throw std::invalid_argument("decode_phase: images of different sizes");
    }
    const double two_pi = 2.0 * std::numbers::pi;
    std::vector<double> sn(static_cast<std::size_t>(n));
    std::vector<double> cs(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
        sn[static_cast<std::size_t>(i)] = std::sin(two_pi * i / n);
        cs[static_cast<std::size_t>(i)] = std::cos(two_pi * i / n);
    }
    PhaseImage out{cv::Mat1f(images[0].size()), cv::Mat1f(images[0].size())};
    for (int y = 0; y < out.position.rows; ++y) {
        for (int x = 0; x < out.position.cols; ++x) {
            double s = 0.0;
            double c = 0.0;
            for (int i = 0; i < n; ++i) {
                const double v = images[static_cast<std::size_t>(i)](y, x);
                s += v * sn[static_cast<std::size_t>(i)];
                c += v * cs[static_cast<std::size_t>(i)];
            }
            double phi = std::atan2(s, c);
            if (phi < 0.0) phi += two_pi;
            out.position(y, x) = static_cast<float>(std::fmod(phi / two_pi * period_px, period_px));
            out.modulation(y, x) = static_cast<float>(2.0 / n * std::hypot(s, c));
        }
    }
    return out;
}

double unwrap_position(double x_gray, double phase_position, double period_px) {
    double d = std::fmod(phase_position - x_gray, period_px);
    if (d < -period_px / 2.0) d += period_px;
    if (d >= period_px / 2.0) d -= period_px;
    return x_gray + d;
}

double mad_sigma(std::vector<float>& abs_devs) {
    if (abs_devs.empty()) return 0.0;
    const auto mid = abs_devs.begin() + static_cast<long>(abs_devs.size() / 2);
    std::nth_element(abs_devs.begin(), mid, abs_devs.end());
    return 1.4826 * *mid;
}

double phase_image_noise(const std::vector<cv::Mat1f>& images, const cv::Mat1b& mask) {
    const std::size_t n = images.size();
    if (n < 4 || n % 2 != 0) return 0.0;
    std::vector<float> dev;
    for (int y = 0; y < mask.rows; ++y) {
        for (int x = 0; x < mask.cols; ++x) {
            if (!mask(y, x)) continue;
            // (I_0 + I_{N/2}) - (I_1 + I_{1+N/2}) = 0 without noise; its sigma is 2 sigma_n.
            const float d = images[0](y, x) + images[n / 2](y, x) - images[1](y, x) - images[1 + n / 2](y, x);
            dev.push_back(std::abs(d));
        }
    }
    return mad_sigma(dev) / 2.0;
}

}  // namespace mogao::autocal
