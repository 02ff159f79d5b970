// SPDX-License-Identifier: Apache-2.0
#include "appliance/warp/inverse_warp.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "appliance/warp/calibration_validation.h"
#include "appliance/warp/warp_sampling.h"

namespace mogao {
namespace {

struct Vec2 {
    double x = 0.0;
    double y = 0.0;
};

// Bilinear patch P(s, t) = a + b s + c t + d s t through corners p00, p10, p01, p11.
struct Patch {
    Vec2 a, b, c, d;
    explicit Patch(const std::array<Vec2, 4>& p)  // p00, p10, p01, p11
        : a(p[0]),
          b{p[1].x - p[0].x, p[1].y - p[0].y},
          c{p[2].x - p[0].x, p[2].y - p[0].y},
          d{p[3].x - p[1].x - p[2].x + p[0].x, p[3].y - p[1].y - p[2].y + p[0].y} {}

    // Newton's method from the cell centre; false when the Jacobian is singular or it diverges.
    bool solve(Vec2 target, double& s, double& t) const {
        s = 0.5;
        t = 0.5;
        for (int iter = 0; iter < 12; ++iter) {
            const double fx = a.x + b.x * s + c.x * t + d.x * s * t - target.x;
            const double fy = a.y + b.y * s + c.y * t + d.y * s * t - target.y;
            const double j11 = b.x + d.x * t, j12 = c.x + d.x * s;
            const double j21 = b.y + d.y * t, j22 = c.y + d.y * s;
            const double det = j11 * j22 - j12 * j21;
            if (!(std::abs(det) > 1e-300)) return false;
            const double ds = (fx * j22 - fy * j12) / det;
            const double dt = (fy * j11 - fx * j21) / det;
            s -= ds;
            t -= dt;
            if (!std::isfinite(s) || !std::isfinite(t)) return false;
            if (std::abs(ds) < 1e-12 && std::abs(dt) < 1e-12) return true;
        }
        return false;
    }
};

}  // namespace

InverseWarp build_inverse_warp(const WarpMap& warp, ImageSize output, ImageSize content) {
    validate_warp(warp, "build_inverse_warp");
    validate_size(output, "build_inverse_warp: output");
    validate_size(content, "build_inverse_warp: content");
    if (warp.size.width > output.width || warp.size.height > output.height) {
        throw std::invalid_argument("build_inverse_warp: warp grid is finer than the output");
    }
    InverseWarp inv;
    inv.content = content;
    inv.xy.assign(static_cast<std::size_t>(content.pixel_count()) * 2, NAN);

    const int gw = warp.size.width;
    const int gh = warp.size.height;
    // A 1-sample axis has no cells along it; nothing can be inverted (a line, not an area).
    if (gw < 2 || gh < 2) return inv;

    const double cw = content.width;
    const double ch = content.height;
    const auto node = [&](int i, int j) -> Vec2 {
        const std::size_t idx =
            (static_cast<std::size_t>(j) * static_cast<std::size_t>(gw) + static_cast<std::size_t>(i)) * 2;
        // Content pixel-index coordinates: content pixel i's centre is at i.
        return {warp.uv[idx] * cw - 0.5, warp.uv[idx + 1] * ch - 0.5};
    };
    constexpr double kSlack = 1e-9;
    for (int j = 0; j + 1 < gh; ++j) {
        for (int i = 0; i + 1 < gw; ++i) {
            const std::array<Vec2, 4> p = {node(i, j), node(i + 1, j), node(i, j + 1), node(i + 1, j + 1)};
            bool finite = true;
            double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
            for (const Vec2& q : p) {
                finite = finite && std::isfinite(q.x) && std::isfinite(q.y);
                x0 = std::min(x0, q.x);
                x1 = std::max(x1, q.x);
                y0 = std::min(y0, q.y);
                y1 = std::max(y1, q.y);
            }
            if (!finite) continue;
            const int px0 = std::max(0, static_cast<int>(std::ceil(std::max(x0, -1.0) - kSlack)));
            const int px1 = std::min(content.width - 1, static_cast<int>(std::floor(std::min(x1, cw) + kSlack)));
            const int py0 = std::max(0, static_cast<int>(std::ceil(std::max(y0, -1.0) - kSlack)));
            const int py1 = std::min(content.height - 1, static_cast<int>(std::floor(std::min(y1, ch) + kSlack)));
            if (px0 > px1 || py0 > py1) continue;
            const Patch patch(p);
            for (int py = py0; py <= py1; ++py) {
                for (int px = px0; px <= px1; ++px) {
                    const std::size_t out = (static_cast<std::size_t>(py) * static_cast<std::size_t>(content.width) +
                                             static_cast<std::size_t>(px)) *
                                            2;
                    if (!std::isnan(inv.xy[out])) continue;  // claimed by an earlier cell
                    double s = 0.0;
                    double t = 0.0;
                    if (!patch.solve({static_cast<double>(px), static_cast<double>(py)}, s, t)) continue;
                    if (s < -kSlack || s > 1.0 + kSlack || t < -kSlack || t > 1.0 + kSlack) continue;
                    inv.xy[out] = static_cast<float>(grid_to_output(i + std::clamp(s, 0.0, 1.0), output.width, gw));
                    inv.xy[out + 1] =
                        static_cast<float>(grid_to_output(j + std::clamp(t, 0.0, 1.0), output.height, gh));
                }
            }
        }
    }
    return inv;
}

}  // namespace mogao
