// SPDX-License-Identifier: Apache-2.0
// Phase-shift patterns, their N-step decoding and the unwrapping by the Gray code (phase_shift.h).
#include "appliance/autocal/phase_shift.h"

#include <algorithm>
#include <cmath>
#include <limits>
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

namespace {

// One pixel's fit: position within the period, modulation and noise gain (phase_shift.h).
struct PixelPhase {
    double phi = 0.0;  // (-pi, pi], radians
    double b = 0.0;
    double gain = std::numeric_limits<double>::infinity();
};

// The N-step estimator (Bruning et al.) where no image clips.
PixelPhase all_images(const std::vector<double>& v, const std::vector<double>& sn, const std::vector<double>& cs) {
    const auto n = static_cast<double>(v.size());
    double s = 0.0;
    double c = 0.0;
    for (std::size_t i = 0; i < v.size(); ++i) {
        s += v[i] * sn[i];
        c += v[i] * cs[i];
    }
    return {std::atan2(s, c), 2.0 / n * std::hypot(s, c), std::sqrt(2.0 / n)};
}

// Least squares over the unclipped images (Chen & Zhang 2016): v_i = a + S sin t_i + C cos t_i.
PixelPhase unclipped_images(const std::vector<double>& v, const std::vector<double>& sn, const std::vector<double>& cs,
                            float clip_level) {
    cv::Matx33d m = cv::Matx33d::zeros();
    cv::Vec3d rhs(0.0, 0.0, 0.0);
    int used = 0;
    for (std::size_t i = 0; i < v.size(); ++i) {
        if (v[i] >= clip_level) continue;
        const cv::Vec3d row(1.0, sn[i], cs[i]);
        m += row * row.t();
        rhs += v[i] * row;
        ++used;
    }
    PixelPhase out;
    // Three unknowns; a nearly singular M (the unclipped shifts bunched together) fits noise, not a sinusoid.
    if (used < 3 || std::abs(cv::determinant(m)) < 1e-6 * used * used * used) return out;
    const cv::Matx33d inv = m.inv(cv::DECOMP_LU);
    const cv::Vec3d x = inv * rhs;
    out.b = std::hypot(x[1], x[2]);
    if (!(out.b > 0.0)) return out;
    out.phi = std::atan2(x[1], x[2]);
    const cv::Vec3d d(0.0, x[2] / (out.b * out.b), -x[1] / (out.b * out.b));  // d phi / d (a, S, C)
    out.gain = out.b * std::sqrt(std::max(0.0, d.dot(inv * d)));
    return out;
}

}  // namespace

PhaseImage decode_phase(const std::vector<cv::Mat1f>& images, double period_px, float clip_level) {
    const int n = static_cast<int>(images.size());
    if (n < 3) throw std::invalid_argument("decode_phase: >= 3 images, got " + std::to_string(n));
    for (const cv::Mat1f& m : images) {
        if (m.size() != images[0].size()) throw std::invalid_argument("decode_phase: images of different sizes");
    }
    const double two_pi = 2.0 * std::numbers::pi;
    const auto count = static_cast<std::size_t>(n);
    std::vector<double> sn(count);
    std::vector<double> cs(count);
    for (std::size_t i = 0; i < count; ++i) {
        sn[i] = std::sin(two_pi * static_cast<double>(i) / n);
        cs[i] = std::cos(two_pi * static_cast<double>(i) / n);
    }
    PhaseImage out{cv::Mat1f(images[0].size()), cv::Mat1f(images[0].size()), cv::Mat1f(images[0].size())};
    std::vector<double> v(count);
    for (int y = 0; y < out.position.rows; ++y) {
        for (int x = 0; x < out.position.cols; ++x) {
            bool clipped = false;
            for (std::size_t i = 0; i < count; ++i) {
                v[i] = images[i](y, x);
                clipped = clipped || v[i] >= clip_level;
            }
            const PixelPhase p = clipped ? unclipped_images(v, sn, cs, clip_level) : all_images(v, sn, cs);
            out.clipped_pixels += clipped ? 1 : 0;
            const double phi = p.phi < 0.0 ? p.phi + two_pi : p.phi;
            out.position(y, x) = static_cast<float>(std::fmod(phi / two_pi * period_px, period_px));
            out.modulation(y, x) = static_cast<float>(p.b);
            out.noise_gain(y, x) = static_cast<float>(p.gain);
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

double phase_image_noise(const std::vector<cv::Mat1f>& images, const cv::Mat1b& mask, float clip_level) {
    const std::size_t n = images.size();
    if (n < 4 || n % 2 != 0) return 0.0;
    std::vector<float> dev;
    for (int y = 0; y < mask.rows; ++y) {
        for (int x = 0; x < mask.cols; ++x) {
            if (!mask(y, x)) continue;
            const float a = images[0](y, x);
            const float b = images[n / 2](y, x);
            const float c = images[1](y, x);
            const float d = images[1 + n / 2](y, x);
            if (std::max({a, b, c, d}) >= clip_level) continue;
            // (I_0 + I_{N/2}) - (I_1 + I_{1+N/2}) = 0 without noise; its sigma is 2 sigma_n.
            dev.push_back(std::abs(a + b - c - d));
        }
    }
    return mad_sigma(dev) / 2.0;
}

}  // namespace mogao::autocal
