// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/denoise/atrous_filter.h"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <string>
#include <thread>

namespace mogao {
namespace {

using Texel = AtrousDenoiser::Texel;
using Geometry = AtrousDenoiser::Geometry;

constexpr float kMinAlbedo = 1e-3f;     // demodulation divides by max(albedo, this)
constexpr float kHuge = 1e30f;          // the scale of a term whose σ is 0: any difference stops
constexpr float kLuminanceEps = 1e-6f;  // ε of w_l [S eq. 5], in radiance units
constexpr float kDepthEps = 1e-3f;      // ε_z of w_z [S eq. 3], relative to the centre's depth
constexpr float kB3[5] = {1.0f / 16, 1.0f / 4, 3.0f / 8, 1.0f / 4, 1.0f / 16};  // [D] §3, B3 spline

std::string size_text(ImageSize s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

// exp(-x) for x >= 0 (NaN and x >= 40 give 0): 2^y by splitting y = -x log2(e) into its integer
// part (the float's exponent field) and its fraction (degree-5 Taylor series of 2^f, relative error
// < 2e-4 — ample for filter weights, which are renormalised).
inline float fast_exp_neg(float x) {
    if (!(x < 40.0f)) return 0.0f;
    const float y = -x * 1.44269504f;
    const float whole = std::floor(y);
    const float f = y - whole;
    const float p =
        1.0f + f * (0.69314718f + f * (0.24022651f + f * (0.05550411f + f * (0.00961813f + f * 0.00133336f))));
    const auto exponent = static_cast<std::uint32_t>(static_cast<int>(whole) + 127);  // >= 69
    return p * std::bit_cast<float>(exponent << 23);
}

inline float luminance(const Texel& t) { return 0.2126f * t.r + 0.7152f * t.g + 0.0722f * t.b; }
inline float finite_or_zero(float v) { return std::isfinite(v) ? v : 0.0f; }

// Runs body(y0, y1) over [0, height) split into `threads` bands; the caller's thread takes the last.
template <typename Body>
void for_row_bands(int height, int threads, const Body& body) {
    threads = std::clamp(threads, 1, std::max(1, height));
    if (threads == 1) {
        body(0, height);
        return;
    }
    std::vector<std::thread> workers;
    workers.reserve(static_cast<std::size_t>(threads - 1));
    for (int t = 0; t + 1 < threads; ++t)
        workers.emplace_back([&body, t, threads, height] { body(height * t / threads, height * (t + 1) / threads); });
    body(height * (threads - 1) / threads, height);
    for (std::thread& w : workers) w.join();
}

// The normal and depth factors of one tap as an exponent: ||n_p - n_q||² / σ_n² [D] plus
// |z_p - z_q| / (σ_z |∇z_p · (p - q)| + ε_z) [S].
struct GeometryWeight {
    float inv_sigma_normal2 = 0.0f;
    float sigma_depth = 0.0f;

    [[nodiscard]] float exponent(const Geometry& p, const Geometry& q, float dx, float dy) const {
        const float ex = p.nx - q.nx, ey = p.ny - q.ny, ez = p.nz - q.nz;
        const float normal_term = (ex * ex + ey * ey + ez * ez) * inv_sigma_normal2;
        const float dz = std::abs(p.depth - q.depth);
        if (dz == 0.0f) return normal_term;
        if (sigma_depth == 0.0f) return kHuge;
        const float allowed = sigma_depth * std::abs(p.dzdx * dx + p.dzdy * dy) + kDepthEps * p.depth;
        return normal_term + dz / allowed;
    }
};

GeometryWeight make_geometry_weight(const AtrousParams& params) {
    GeometryWeight g;
    g.inv_sigma_normal2 = params.sigma_normal > 0.0f ? 1.0f / (params.sigma_normal * params.sigma_normal) : kHuge;
    g.sigma_depth = params.sigma_depth;
    return g;
}

// One-sided depth difference of smaller magnitude (so an edge beside p does not inflate its slope);
// 0 when neither neighbour is a surface.
float depth_slope(float centre, float before, float after) {
    const bool has_before = before > 0.0f, has_after = after > 0.0f;
    if (!has_before && !has_after) return 0.0f;
    if (!has_before) return after - centre;
    if (!has_after) return centre - before;
    const float back = centre - before, forward = after - centre;
    return std::abs(back) < std::abs(forward) ? back : forward;
}

Status check_sigma(const char* name, float value) {
    if (std::isfinite(value) && value >= 0.0f) return {};
    return make_error(
        EINVAL, std::string("denoise: params.") + name + " = " + std::to_string(value) + " must be finite and >= 0");
}

Status check_guides(const GuideBuffers& guides, ImageSize size) {
    const auto n = static_cast<std::size_t>(size.pixel_count());
    if (guides.size != size)
        return make_error(EINVAL,
                          "denoise: guides are " + size_text(guides.size) + ", the image is " + size_text(size));
    if (guides.hit.size() != n || guides.depth.size() != n || guides.albedo.size() != 3 * n ||
        guides.normal.size() != 3 * n) {
        return make_error(EINVAL, "denoise: guide buffers must hold W*H = " + std::to_string(n) +
                                      " values (hit, depth) and W*H*3 (albedo, normal); got hit " +
                                      std::to_string(guides.hit.size()) + ", depth " +
                                      std::to_string(guides.depth.size()) + ", albedo " +
                                      std::to_string(guides.albedo.size()) + ", normal " +
                                      std::to_string(guides.normal.size()));
    }
    for (std::size_t i = 0; i < n; ++i) {
        if (guides.hit[i] == 0) continue;
        const float z = guides.depth[i];
        if (!(std::isfinite(z) && z > 0.0f)) {
            return make_error(EINVAL, "denoise: guides.depth at pixel " + std::to_string(i) + " = " +
                                          std::to_string(z) + " must be finite and > 0 where hit = 1");
        }
    }
    return {};
}

}  // namespace

Status validate_denoise_input(const RgbFloatImage& noisy, const GuideBuffers& guides, const AtrousParams& params) {
    const ImageSize size = noisy.size;
    if (size.width <= 0 || size.height <= 0)
        return make_error(EINVAL, "denoise: image is " + size_text(size) + ", empty");
    if (noisy.pixels.size() != static_cast<std::size_t>(size.pixel_count()) * 3) {
        return make_error(EINVAL, "denoise: image " + size_text(size) + " holds " +
                                      std::to_string(noisy.pixels.size()) +
                                      " values, W*H*3 = " + std::to_string(size.pixel_count() * 3) + " expected");
    }
    if (params.iterations < 0 || params.iterations > AtrousParams::kMaxIterations) {
        return make_error(EINVAL, "denoise: params.iterations = " + std::to_string(params.iterations) +
                                      " is outside [0, " + std::to_string(AtrousParams::kMaxIterations) + "]");
    }
    if (params.threads < 0)
        return make_error(EINVAL, "denoise: params.threads = " + std::to_string(params.threads) + " must be >= 0");
    for (const auto& [name, value] :
         {std::pair{"sigma_colour", params.sigma_colour}, std::pair{"sigma_normal", params.sigma_normal},
          std::pair{"sigma_depth", params.sigma_depth}}) {
        if (Status s = check_sigma(name, value); !s.ok()) return s;
    }
    return check_guides(guides, size);
}

namespace {

// Demodulates the colour and fills the geometry (normal, depth and its slope) of every pixel.
void prepare(const RgbFloatImage& noisy, const GuideBuffers& guides, std::vector<Texel>& texels,
             std::vector<Geometry>& geometry, int threads) {
    const int w = noisy.size.width, h = noisy.size.height;
    const auto depth_at = [&](int x, int y) {
        if (x < 0 || y < 0 || x >= w || y >= h) return 0.0f;
        const std::size_t i = guides.pixel(x, y);
        return guides.hit[i] != 0 ? guides.depth[i] : 0.0f;
    };
    for_row_bands(h, threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y) {
            for (int x = 0; x < w; ++x) {
                const std::size_t i = guides.pixel(x, y);
                const float* c = noisy.pixels.data() + 3 * i;
                Texel t{finite_or_zero(c[0]), finite_or_zero(c[1]), finite_or_zero(c[2]), 0.0f};
                Geometry g{};
                if (guides.hit[i] != 0) {
                    const float* a = guides.albedo.data() + 3 * i;
                    t.r /= std::max(a[0], kMinAlbedo);
                    t.g /= std::max(a[1], kMinAlbedo);
                    t.b /= std::max(a[2], kMinAlbedo);
                    const float* n = guides.normal.data() + 3 * i;
                    const float z = guides.depth[i];
                    g = {n[0],
                         n[1],
                         n[2],
                         z,
                         depth_slope(z, depth_at(x - 1, y), depth_at(x + 1, y)),
                         depth_slope(z, depth_at(x, y - 1), depth_at(x, y + 1))};
                }
                texels[i] = t;
                geometry[i] = g;
            }
        }
    });
}

// Spatial luminance variance of each surface pixel over its 5x5 neighbourhood on the same surface
// (weights: the geometry terms only) — [S] §4.2's estimate for frames without history.
void estimate_variance(ImageSize size, const GeometryWeight& gw, const std::vector<Geometry>& geometry,
                       std::vector<Texel>& texels, int threads) {
    const int w = size.width, h = size.height;
    for_row_bands(h, threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y) {
            for (int x = 0; x < w; ++x) {
                const std::size_t i = static_cast<std::size_t>(y) * w + x;
                const Geometry& gp = geometry[i];
                if (gp.depth == 0.0f) continue;
                float sw = 0.0f, s1 = 0.0f, s2 = 0.0f;
                for (int qy = std::max(0, y - 2); qy <= std::min(h - 1, y + 2); ++qy) {
                    for (int qx = std::max(0, x - 2); qx <= std::min(w - 1, x + 2); ++qx) {
                        const std::size_t j = static_cast<std::size_t>(qy) * w + qx;
                        if (geometry[j].depth == 0.0f) continue;
                        const float wt = fast_exp_neg(gw.exponent(gp, geometry[j], float(qx - x), float(qy - y)));
                        const float l = luminance(texels[j]);
                        sw += wt;
                        s1 += wt * l;
                        s2 += wt * l * l;
                    }
                }
                const float mean = s1 / sw;
                texels[i].variance = std::max(0.0f, s2 / sw - mean * mean);
            }
        }
    });
}

// g3x3(Var) of [S] eq. 5: the variance blurred by (1/4, 1/2, 1/4)² over surface pixels.
void blur_variance(ImageSize size, const std::vector<Texel>& texels, const std::vector<Geometry>& geometry,
                   std::vector<float>& out, int threads) {
    constexpr float k[3] = {0.25f, 0.5f, 0.25f};
    const int w = size.width, h = size.height;
    for_row_bands(h, threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y) {
            for (int x = 0; x < w; ++x) {
                const std::size_t i = static_cast<std::size_t>(y) * w + x;
                if (geometry[i].depth == 0.0f) continue;
                float sw = 0.0f, sv = 0.0f;
                for (int dy = -1; dy <= 1; ++dy) {
                    const int qy = y + dy;
                    if (qy < 0 || qy >= h) continue;
                    for (int dx = -1; dx <= 1; ++dx) {
                        const int qx = x + dx;
                        if (qx < 0 || qx >= w) continue;
                        const std::size_t j = static_cast<std::size_t>(qy) * w + qx;
                        if (geometry[j].depth == 0.0f) continue;
                        const float wt = k[dx + 1] * k[dy + 1];
                        sw += wt;
                        sv += wt * texels[j].variance;
                    }
                }
                out[i] = sv / sw;
            }
        }
    });
}

struct Level {
    int step = 1;
    float sigma_colour = 0.0f;
    GeometryWeight geometry;
};

// One à-trous level [D]: every surface pixel becomes the weighted mean of its 5x5 taps at `step`.
void filter_level(ImageSize size, const Level& level, const std::vector<Texel>& src,
                  const std::vector<Geometry>& geometry, const std::vector<float>& blurred_variance,
                  std::vector<Texel>& dst, int threads) {
    const int w = size.width, h = size.height, step = level.step;
    for_row_bands(h, threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y) {
            for (int x = 0; x < w; ++x) {
                const std::size_t i = static_cast<std::size_t>(y) * w + x;
                const Geometry& gp = geometry[i];
                if (gp.depth == 0.0f) {
                    dst[i] = src[i];
                    continue;
                }
                const float lp = luminance(src[i]);
                const float colour_scale =
                    level.sigma_colour > 0.0f
                        ? 1.0f / (level.sigma_colour * std::sqrt(blurred_variance[i]) + kLuminanceEps)
                        : kHuge;
                float sw = 0.0f, sr = 0.0f, sg = 0.0f, sb = 0.0f, sv = 0.0f;
                for (int ky = -2; ky <= 2; ++ky) {
                    const int qy = y + ky * step;
                    if (qy < 0 || qy >= h) continue;
                    for (int kx = -2; kx <= 2; ++kx) {
                        const int qx = x + kx * step;
                        if (qx < 0 || qx >= w) continue;
                        const std::size_t j = static_cast<std::size_t>(qy) * w + qx;
                        const Geometry& gq = geometry[j];
                        if (gq.depth == 0.0f) continue;
                        const Texel& q = src[j];
                        const float dl = std::abs(lp - luminance(q));
                        const float e = (dl == 0.0f ? 0.0f : dl * colour_scale) +
                                        level.geometry.exponent(gp, gq, float(kx * step), float(ky * step));
                        const float wt = kB3[kx + 2] * kB3[ky + 2] * fast_exp_neg(e);
                        sw += wt;
                        sr += wt * q.r;
                        sg += wt * q.g;
                        sb += wt * q.b;
                        sv += wt * wt * q.variance;
                    }
                }
                dst[i] = {sr / sw, sg / sw, sb / sw, sv / (sw * sw)};
            }
        }
    });
}

}  // namespace

Status AtrousDenoiser::run(const RgbFloatImage& noisy, const GuideBuffers& guides, const AtrousParams& params,
                           RgbFloatImage& out) {
    if (Status s = validate_denoise_input(noisy, guides, params); !s.ok()) return s;
    const ImageSize size = noisy.size;
    const auto n = static_cast<std::size_t>(size.pixel_count());
    const int threads =
        params.threads > 0 ? params.threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
    if (params.iterations == 0) {
        out = noisy;
        return {};
    }
    ping_.resize(n);
    pong_.resize(n);
    geometry_.resize(n);
    blurred_variance_.resize(n);
    const GeometryWeight gw = make_geometry_weight(params);
    prepare(noisy, guides, ping_, geometry_, threads);
    estimate_variance(size, gw, geometry_, ping_, threads);
    for (int level = 0; level < params.iterations; ++level) {
        blur_variance(size, ping_, geometry_, blurred_variance_, threads);
        filter_level(size, Level{1 << level, params.sigma_colour, gw}, ping_, geometry_, blurred_variance_, pong_,
                     threads);
        std::swap(ping_, pong_);
    }
    out.size = size;
    out.pixels.resize(3 * n);
    for (std::size_t i = 0; i < n; ++i) {
        const Texel& t = ping_[i];
        float* o = out.pixels.data() + 3 * i;
        if (guides.hit[i] == 0) {
            o[0] = t.r, o[1] = t.g, o[2] = t.b;
            continue;
        }
        const float* a = guides.albedo.data() + 3 * i;
        o[0] = t.r * std::max(a[0], kMinAlbedo);
        o[1] = t.g * std::max(a[1], kMinAlbedo);
        o[2] = t.b * std::max(a[2], kMinAlbedo);
    }
    return {};
}

Result<RgbFloatImage> denoise_atrous(const RgbFloatImage& noisy, const GuideBuffers& guides,
                                     const AtrousParams& params) {
    AtrousDenoiser denoiser;
    RgbFloatImage out;
    if (Status s = denoiser.run(noisy, guides, params, out); !s.ok()) return s.error();
    return out;
}

}  // namespace mogao
