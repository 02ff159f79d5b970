// SPDX-License-Identifier: Apache-2.0
#include "appliance/warp/warp_sampling.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace mogao {
namespace {

// The two samples and the weight of the second one along one axis.
struct Taps {
    int i0 = 0;
    int i1 = 0;
    double f = 0.0;
};

Taps taps_at(double pixel, int output_extent, int grid_extent) {
    const double g =
        std::clamp(output_to_grid(pixel, output_extent, grid_extent), 0.0, static_cast<double>(grid_extent - 1));
    Taps t;
    t.i0 = static_cast<int>(std::floor(g));
    t.i1 = std::min(t.i0 + 1, grid_extent - 1);
    t.f = g - t.i0;
    return t;
}

}  // namespace

double output_to_grid(double x, int output_extent, int grid_extent) {
    return (x + 0.5) * static_cast<double>(grid_extent) / static_cast<double>(output_extent) - 0.5;
}

double grid_to_output(double g, int output_extent, int grid_extent) {
    return (g + 0.5) * static_cast<double>(output_extent) / static_cast<double>(grid_extent) - 0.5;
}

ContentUv sample_warp(const WarpMap& warp, ImageSize output, int x, int y) {
    return sample_warp_at(warp, output, x, y);
}

ContentUv sample_warp_at(const WarpMap& warp, ImageSize output, double x, double y) {
    const Taps tx = taps_at(x, output.width, warp.size.width);
    const Taps ty = taps_at(y, output.height, warp.size.height);
    const int xs[2] = {tx.i0, tx.i1};
    const int ys[2] = {ty.i0, ty.i1};
    const double wx[2] = {1.0 - tx.f, tx.f};
    const double wy[2] = {1.0 - ty.f, ty.f};
    double u = 0.0;
    double v = 0.0;
    for (int b = 0; b < 2; ++b) {
        for (int a = 0; a < 2; ++a) {
            const double w = wx[a] * wy[b];
            if (w == 0.0) continue;  // a NaN neighbour with zero weight must not poison the result
            const std::size_t idx = (static_cast<std::size_t>(ys[b]) * static_cast<std::size_t>(warp.size.width) +
                                     static_cast<std::size_t>(xs[a])) *
                                    2;
            const float su = warp.uv[idx];
            const float sv = warp.uv[idx + 1];
            if (std::isnan(su) || std::isnan(sv)) return {NAN, NAN};
            u += w * su;
            v += w * sv;
        }
    }
    return {static_cast<float>(u), static_cast<float>(v)};
}

float sample_blend(const BlendMask& blend, ImageSize output, int x, int y) {
    const Taps tx = taps_at(x, output.width, blend.size.width);
    const Taps ty = taps_at(y, output.height, blend.size.height);
    const auto at = [&](int gx, int gy) {
        return static_cast<double>(
            blend.weight[static_cast<std::size_t>(gy) * static_cast<std::size_t>(blend.size.width) +
                         static_cast<std::size_t>(gx)]);
    };
    const double top = at(tx.i0, ty.i0) * (1.0 - tx.f) + at(tx.i1, ty.i0) * tx.f;
    const double bottom = at(tx.i0, ty.i1) * (1.0 - tx.f) + at(tx.i1, ty.i1) * tx.f;
    return static_cast<float>(top * (1.0 - ty.f) + bottom * ty.f);
}

std::array<float, 3> sample_beta(const BlackOffset& beta, ImageSize output, int x, int y) {
    if (beta.size.width == 0 || beta.size.height == 0) return {0.0F, 0.0F, 0.0F};
    const Taps tx = taps_at(x, output.width, beta.size.width);
    const Taps ty = taps_at(y, output.height, beta.size.height);
    std::array<float, 3> out{};
    for (std::size_t c = 0; c < 3; ++c) {
        const auto at = [&](int gx, int gy) {
            return static_cast<double>(
                beta.rgb[(static_cast<std::size_t>(gy) * static_cast<std::size_t>(beta.size.width) +
                          static_cast<std::size_t>(gx)) *
                             3 +
                         c]);
        };
        const double top = at(tx.i0, ty.i0) * (1.0 - tx.f) + at(tx.i1, ty.i0) * tx.f;
        const double bottom = at(tx.i0, ty.i1) * (1.0 - tx.f) + at(tx.i1, ty.i1) * tx.f;
        out[c] = static_cast<float>(top * (1.0 - ty.f) + bottom * ty.f);
    }
    return out;
}

}  // namespace mogao
