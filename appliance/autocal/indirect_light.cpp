// SPDX-License-Identifier: Apache-2.0
#include "appliance/autocal/indirect_light.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "appliance/autocal/bundle_adjust.h"
#include "appliance/autocal/screen_geometry.h"
#include "appliance/warp/warp_sampling.h"

namespace mogao::autocal {
namespace {

void check(const ScreenModel& screen, const std::vector<DeviceModel>& projectors,
           const ScreenCalibration& calibration) {
    if (!(screen.interreflection >= 0.0 && screen.interreflection < 1.0))
        throw std::invalid_argument("indirect light: screen interreflection " + std::to_string(screen.interreflection) +
                                    " outside [0, 1)");
    if (projectors.size() != calibration.projectors.size())
        throw std::invalid_argument("indirect light: " + std::to_string(projectors.size()) + " projector models for " +
                                    std::to_string(calibration.projectors.size()) + " calibrated projectors");
}

// 1 / G at screen point (theta, h): the blend-weighted mean over the projectors whose shown pixel lands there of
// 1 / (the gain toward the viewer of that projector's light); 0 where none shows content.
double inverse_gain_at(const ScreenModel& screen, const std::vector<DeviceModel>& projectors,
                       const ScreenCalibration& calibration, double theta, double h) {
    const Eigen::Vector3d p = screen_position(screen, theta, h);
    double weights = 0.0, sum = 0.0;
    for (std::size_t k = 0; k < projectors.size(); ++k) {
        const DeviceModel& d = projectors[k];
        const Eigen::Vector3d q = d.rotation.transpose() * (p - d.position_m);  // device frame
        if (q.z() <= 0.0) continue;                                             // behind the lens
        const Eigen::Vector2d xy = device_image(d, q);
        if (!xy.allFinite()) continue;
        const ProjectorCalibration& pc = calibration.projectors[k];
        const double sx = static_cast<double>(pc.output.width) / d.resolution.width;
        const double sy = static_cast<double>(pc.output.height) / d.resolution.height;
        const int x = static_cast<int>(std::floor(xy.x() * sx)), y = static_cast<int>(std::floor(xy.y() * sy));
        if (x < 0 || y < 0 || x >= pc.output.width || y >= pc.output.height) continue;
        if (!sample_warp(pc.warp, pc.output, x, y).valid()) continue;
        const double w = sample_blend(pc.blend, pc.output, x, y);
        if (!(w > 0.0)) continue;
        weights += w;
        sum += w / screen_gain_at(screen, theta, h, d.position_m, screen.viewer_m);
    }
    return weights > 0.0 ? sum / weights : 0.0;
}

}  // namespace

IndirectLight::IndirectLight(const ScreenModel& screen, const std::vector<DeviceModel>& projectors,
                             const ScreenCalibration& calibration, double patch_m)
    : bounce_(screen, patch_m), rho_(screen.interreflection) {
    check(screen, projectors, calibration);
    const double arc = screen.arc_deg * std::numbers::pi / 180.0;
    const double height = screen.top_m - screen.bottom_m;
    inverse_gain_.resize(static_cast<std::size_t>(bounce_.patches()), 0.0);
    if (!active()) return;
    for (int r = 0; r < rows(); ++r) {
        for (int c = 0; c < columns(); ++c) {
            const double theta = -arc / 2.0 + (c + 0.5) * arc / columns();
            const double h = screen.bottom_m + (r + 0.5) * height / rows();
            inverse_gain_[static_cast<std::size_t>(r * columns() + c)] =
                inverse_gain_at(screen, projectors, calibration, theta, h);
        }
    }
    const std::size_t n = inverse_gain_.size();
    const std::vector<double>& form = bounce_.form_factors();
    transfer_.resize(n * n);
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < n; ++j)
            transfer_[j * n + i] = static_cast<float>(rho_ * form[i * n + j] * inverse_gain_[j]);
}

void IndirectLight::indirect(const std::array<std::vector<float>, 3>& c, std::array<std::vector<float>, 3>& out) const {
    const std::size_t n = inverse_gain_.size();
    for (std::vector<float>& o : out) std::fill(o.begin(), o.end(), 0.0F);
    float* __restrict o0 = out[0].data();
    float* __restrict o1 = out[1].data();
    float* __restrict o2 = out[2].data();
    // Column by column (what patch j throws onto every patch): a sum of scaled columns, which the compiler
    // vectorises without reordering any sum; dark patches throw nothing and are skipped.
    for (std::size_t j = 0; j < n; ++j) {
        const float r = c[0][j], g = c[1][j], b = c[2][j];
        if (r == 0.0F && g == 0.0F && b == 0.0F) continue;
        const float* __restrict t = &transfer_[j * n];
        for (std::size_t i = 0; i < n; ++i) {
            o0[i] += t[i] * r;
            o1[i] += t[i] * g;
            o2[i] += t[i] * b;
        }
    }
}

RgbFloatImage IndirectLight::field(const RgbFloatImage& patches) const {
    if (patches.size.width != columns() || patches.size.height != rows())
        throw std::invalid_argument("indirect light: patch means of " + std::to_string(patches.size.width) + "x" +
                                    std::to_string(patches.size.height) + " for a field of " +
                                    std::to_string(columns()) + "x" + std::to_string(rows()));
    if (!active()) return {};
    const std::size_t n = inverse_gain_.size();
    // Patch values bottom row first (ScreenBounce's order), one plane per channel; the image's row 0 is the top.
    std::array<std::vector<float>, 3> content, shown, f;
    for (std::size_t ch = 0; ch < 3; ++ch) {
        content[ch].resize(n);
        f[ch].resize(n);
    }
    for (int r = 0; r < rows(); ++r) {
        for (int c = 0; c < columns(); ++c) {
            const float* px = patches.at(c, rows() - 1 - r);
            for (std::size_t ch = 0; ch < 3; ++ch) content[ch][static_cast<std::size_t>(r * columns() + c)] = px[ch];
        }
    }
    // Two Jacobi steps: f0 = I[c] - I0, c' = max(c - f0, 0), f = I[c'] - I0 (the header's fixed point).
    shown = content;
    for (int step = 0; step < 2; ++step) {
        indirect(shown, f);
        for (std::size_t ch = 0; ch < 3; ++ch) {
            float least = std::numeric_limits<float>::infinity();
            for (std::size_t j = 0; j < n; ++j)
                if (inverse_gain_[j] > 0.0) least = std::min(least, f[ch][j]);
            if (!std::isfinite(least)) least = 0.0F;
            for (std::size_t j = 0; j < n; ++j) {
                f[ch][j] = std::max(0.0F, f[ch][j] - least);
                shown[ch][j] = std::max(0.0F, content[ch][j] - f[ch][j]);
            }
        }
    }
    RgbFloatImage out(ImageSize{columns(), rows()});
    for (int r = 0; r < rows(); ++r) {
        for (int c = 0; c < columns(); ++c) {
            float* px = out.at(c, rows() - 1 - r);
            for (std::size_t ch = 0; ch < 3; ++ch) px[ch] = f[ch][static_cast<std::size_t>(r * columns() + c)];
        }
    }
    return out;
}

RgbFloatImage IndirectLight::flat_field(double level) const {
    return field(RgbFloatImage(ImageSize{columns(), rows()}, static_cast<float>(level)));
}

RgbFloatImage IndirectLight::patch_means(const RgbFloatImage& content_linear, int samples) const {
    if (content_linear.size.width <= 0 || content_linear.size.height <= 0 ||
        content_linear.pixels.size() != static_cast<std::size_t>(content_linear.size.pixel_count()) * 3)
        throw std::invalid_argument("indirect light: empty or malformed content image");
    samples = std::clamp(samples, 1, 64);
    RgbFloatImage out(ImageSize{columns(), rows()});
    const ImageSize s = content_linear.size;
    for (int r = 0; r < rows(); ++r) {
        for (int c = 0; c < columns(); ++c) {
            std::array<double, 3> sum{};
            for (int j = 0; j < samples; ++j) {
                for (int i = 0; i < samples; ++i) {
                    const double u = (c + (i + 0.5) / samples) / columns();
                    const double v = (r + (j + 0.5) / samples) / rows();
                    const int x = std::clamp(static_cast<int>(u * s.width), 0, s.width - 1);
                    const int y = std::clamp(static_cast<int>(v * s.height), 0, s.height - 1);
                    const float* px = content_linear.at(x, y);
                    for (std::size_t ch = 0; ch < 3; ++ch) sum[ch] += px[ch];
                }
            }
            float* o = out.at(c, r);
            for (std::size_t ch = 0; ch < 3; ++ch) o[ch] = static_cast<float>(sum[ch] / (samples * samples));
        }
    }
    return out;
}

}  // namespace mogao::autocal
