// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/denoise/atrous_filter.h"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "renderfarm/denoise/float_lanes.h"

namespace mogao {
namespace {

constexpr float kHuge = 1e30f;          // the scale of a term whose σ is 0: any difference stops
constexpr float kLuminanceEps = 1e-6f;  // ε of w_l [S eq. 5], in radiance units
constexpr float kDepthEps = 1e-3f;      // ε_z of w_z [S eq. 3], relative to the centre's depth
constexpr float kMaxExponent = 40.0f;   // exp(-40) = 4e-18: a weight of 0 for any purpose
constexpr float kB3[5] = {1.0f / 16, 1.0f / 4, 3.0f / 8, 1.0f / 4, 1.0f / 16};  // [D] §3, B3 spline

std::string size_text(ImageSize s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

inline float finite_or_zero(float v) { return std::isfinite(v) ? v : 0.0f; }
inline float luminance(float r, float g, float b) { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }

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

Status check_variance(const RgbFloatImage& variance, ImageSize size) {
    if (variance.size != size || variance.pixels.size() != static_cast<std::size_t>(size.pixel_count()) * 3) {
        return make_error(EINVAL, "denoise: variance is " + size_text(variance.size) + " with " +
                                      std::to_string(variance.pixels.size()) + " values, the image " + size_text(size) +
                                      " (W*H*3 values expected)");
    }
    for (std::size_t i = 0; i < variance.pixels.size(); ++i) {
        const float v = variance.pixels[i];
        if (!(std::isfinite(v) && v >= 0.0f)) {
            return make_error(EINVAL, "denoise: variance at pixel " + std::to_string(i / 3) + " = " +
                                          std::to_string(v) + " must be finite and >= 0");
        }
    }
    return {};
}

Status check_luminance_variance(const std::vector<float>& variance, ImageSize size, bool colour_variance_too) {
    if (colour_variance_too)
        return make_error(EINVAL, "denoise: variance and luminance_variance are both given (one or the other)");
    if (variance.size() != static_cast<std::size_t>(size.pixel_count())) {
        return make_error(EINVAL, "denoise: luminance_variance holds " + std::to_string(variance.size()) +
                                      " values, the image " + size_text(size) + " (W*H expected)");
    }
    for (std::size_t i = 0; i < variance.size(); ++i) {
        if (!std::isfinite(variance[i])) {
            return make_error(EINVAL, "denoise: luminance_variance at pixel " + std::to_string(i) + " = " +
                                          std::to_string(variance[i]) + " must be finite");
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

// The planes of AtrousDenoiser::planes_ (W*H floats each).
struct Signal {
    float* r;
    float* g;
    float* b;
    float* var;  // luminance variance
    float* lum;
};
struct Geometry {
    float* nx;
    float* ny;
    float* nz;
    float* z;     // metres, 0 = sky
    float* dzdx;  // depth slope, metres per pixel
    float* dzdy;
    float* mask;  // 1 = surface, 0 = sky
};
constexpr std::size_t kPlanes = 5 + 5 + 7 + 1;

struct Planes {
    Signal ping, pong;
    Geometry geometry;
    float* colour_scale;  // 1 / (σ_l sqrt(g3x3(Var)) + ε) of the current level
};

// Floats of zeros before and after each plane: the filter's chunks of up to eight pixels read taps
// up to 2 x the largest step beyond a row's ends (and a chunk up to 7 pixels past the last pixel),
// with weight 0; the margin keeps those reads inside the storage.
constexpr std::size_t kPlaneMargin = (std::size_t{2} << AtrousParams::kMaxIterations) + 16;

Planes make_planes(std::vector<float>& storage, std::size_t n) {
    const std::size_t stride = n + 2 * kPlaneMargin;
    storage.resize(kPlanes * stride);
    for (std::size_t k = 0; k < kPlanes; ++k) {  // the margins only: every plane's pixels are written before use
        float* margin_before = storage.data() + k * stride;
        std::fill(margin_before, margin_before + kPlaneMargin, 0.0f);
        std::fill(margin_before + kPlaneMargin + n, margin_before + stride, 0.0f);
    }
    float* p = storage.data() + kPlaneMargin;
    const auto next = [&] { return std::exchange(p, p + stride); };
    Planes planes{};
    planes.ping = {next(), next(), next(), next(), next()};
    planes.pong = {next(), next(), next(), next(), next()};
    planes.geometry = {next(), next(), next(), next(), next(), next(), next()};
    planes.colour_scale = next();
    return planes;
}

// The exponent of the normal and depth factors: ||n_p - n_q||² / σ_n² [D] plus
// |z_p - z_q| / (σ_z |∇z_p · (p - q)| + ε_z) [S]. σ = 0 turns a factor into "exactly equal only".
struct GeometryWeight {
    float inv_sigma_normal2 = 0.0f;
    float sigma_depth = 0.0f;
    float depth_eps = kDepthEps;
};

GeometryWeight make_geometry_weight(const AtrousParams& params) {
    GeometryWeight g;
    g.inv_sigma_normal2 = params.sigma_normal > 0.0f ? 1.0f / (params.sigma_normal * params.sigma_normal) : kHuge;
    g.sigma_depth = params.sigma_depth;
    g.depth_eps = params.sigma_depth > 0.0f ? kDepthEps : 1e-30f;
    return g;
}

// Demodulates the colour and fills the geometry (normal, depth and its slope) of every pixel.
void prepare(const RgbFloatImage& noisy, const GuideBuffers& guides, const Planes& planes, int threads) {
    const int w = noisy.size.width, h = noisy.size.height;
    const auto depth_at = [&](int x, int y) {
        if (x < 0 || y < 0 || x >= w || y >= h) return 0.0f;
        const std::size_t i = guides.pixel(x, y);
        return guides.hit[i] != 0 ? guides.depth[i] : 0.0f;
    };
    const Signal& s = planes.ping;
    const Geometry& g = planes.geometry;
    for_row_bands(h, threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y) {
            for (int x = 0; x < w; ++x) {
                const std::size_t i = guides.pixel(x, y);
                const float* c = noisy.pixels.data() + 3 * i;
                float r = finite_or_zero(c[0]), gr = finite_or_zero(c[1]), b = finite_or_zero(c[2]);
                const bool hit = guides.hit[i] != 0;
                if (hit) {
                    const float* a = guides.albedo.data() + 3 * i;
                    r /= std::max(a[0], kDemodulationMinAlbedo);
                    gr /= std::max(a[1], kDemodulationMinAlbedo);
                    b /= std::max(a[2], kDemodulationMinAlbedo);
                }
                s.r[i] = r, s.g[i] = gr, s.b[i] = b, s.var[i] = 0.0f, s.lum[i] = luminance(r, gr, b);
                const float* n = guides.normal.data() + 3 * i;
                const float z = hit ? guides.depth[i] : 0.0f;
                g.nx[i] = hit ? n[0] : 0.0f, g.ny[i] = hit ? n[1] : 0.0f, g.nz[i] = hit ? n[2] : 0.0f;
                g.z[i] = z;
                g.dzdx[i] = hit ? depth_slope(z, depth_at(x - 1, y), depth_at(x + 1, y)) : 0.0f;
                g.dzdy[i] = hit ? depth_slope(z, depth_at(x, y - 1), depth_at(x, y + 1)) : 0.0f;
                g.mask[i] = hit ? 1.0f : 0.0f;
            }
        }
    });
}

// The columns x0, x0 + 1, ... of a chunk's lanes.
template <typename F>
MOGAO_ALWAYS_INLINE inline F lane_columns(int x0) {
    F x{};
    for (int k = 0; k < lanes::kWidth<F>; ++k) x[k] = static_cast<float>(x0 + k);
    return x;
}

// `wt` with the lanes whose tap column (lane_x + ox) lies outside [0, w) set to 0 (a row's ends); the
// chunk starts at column x0.
template <typename F>
MOGAO_ALWAYS_INLINE inline F inside_columns(F wt, const F& lane_x, int x0, int ox, int w) {
    using lanes::select, lanes::splat;
    if (x0 + ox >= 0 && x0 + lanes::kWidth<F> - 1 + ox < w) return wt;
    const F tap_x = lane_x + static_cast<float>(ox);
    return select((tap_x >= splat<F>(0.0f)) & (tap_x < splat<F>(static_cast<float>(w))), wt, F{});
}

// The centre values of a chunk of pixels [x0, x0 + W) of a row starting at pixel index p (W the
// lanes of F) that every tap's geometry weight reads, held in registers while the taps are walked.
template <typename F>
struct ChunkCentre {
    F nx, ny, nz, z, dzdx, dzdy, z_eps, lane_x;
    MOGAO_ALWAYS_INLINE ChunkCentre(const Geometry& g, const GeometryWeight& gw, std::size_t p, int x0)
        : nx(lanes::load<F>(g.nx + p)),
          ny(lanes::load<F>(g.ny + p)),
          nz(lanes::load<F>(g.nz + p)),
          z(lanes::load<F>(g.z + p)),
          dzdx(lanes::load<F>(g.dzdx + p)),
          dzdy(lanes::load<F>(g.dzdy + p)),
          z_eps(gw.depth_eps * z),
          lane_x(lane_columns<F>(x0)) {}

    // The geometry exponent of tap q, offset (fx, fy) pixels (GeometryWeight's formula); NaN for a
    // sky centre (0/0), which callers clamp.
    MOGAO_ALWAYS_INLINE F geometry_exponent(const Geometry& g, const GeometryWeight& gw, std::ptrdiff_t q, float fx,
                                            float fy) const {
        using lanes::abs, lanes::load;
        const F ex = nx - load<F>(g.nx + q), ey = ny - load<F>(g.ny + q), ez = nz - load<F>(g.nz + q);
        const F allowed = gw.sigma_depth * abs(dzdx * fx + dzdy * fy) + z_eps;
        return (ex * ex + ey * ey + ez * ez) * gw.inv_sigma_normal2 + abs(z - load<F>(g.z + q)) / allowed;
    }
};

// Sums over the 5x5 neighbourhood on the same surface of the pixels [x0, x0 + W) of row y (W the
// lanes of F; the last chunk of a row may run past its end, those lanes are not used), the weights
// the geometry terms only (GeometryWeight's formula, [S] §4.2): sw = Σ w, s1 = Σ w a and, with
// kSquares, s2 = Σ w a². A tap outside the image adds nothing. The chunk's centre values and sums stay
// in registers across the taps, as in filter_chunk_body.
template <typename F, bool kSquares>
MOGAO_ALWAYS_INLINE inline void surface_sums(ImageSize size, const GeometryWeight& gw, const Geometry& g,
                                             const float* a, int y, int x0, F& sw, F& s1, F& s2) {
    using lanes::exp_neg, lanes::load, lanes::select, lanes::splat;
    const int w = size.width, h = size.height;
    const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x0);
    const ChunkCentre<F> c(g, gw, p, x0);
    for (int oy = -2; oy <= 2; ++oy) {
        if (y + oy < 0 || y + oy >= h) continue;
        for (int ox = -2; ox <= 2; ++ox) {
            const std::ptrdiff_t q = static_cast<std::ptrdiff_t>(p) + static_cast<std::ptrdiff_t>(oy) * w + ox;
            F e = c.geometry_exponent(g, gw, q, static_cast<float>(ox), static_cast<float>(oy));
            e = select(e < splat<F>(kMaxExponent), e, splat<F>(kMaxExponent));  // NaN (sky p) gives the limit
            const F wt = inside_columns(load<F>(g.mask + q) * exp_neg(e), c.lane_x, x0, ox, w);
            const F aq = load<F>(a + q);
            sw += wt;
            s1 += wt * aq;
            if constexpr (kSquares) s2 += wt * aq * aq;
        }
    }
}

// Luminance variance of row y's surface pixels into ping.var: `given`'s value where it is >= 0 (a
// temporal estimate), else (or with no `given`) the spatial variance over the pixel's 5x5
// neighbourhood on the same surface — [S] §4.2's estimate for frames without history. A chunk of
// pixels that all have a given value skips the spatial sums.
template <typename F>
MOGAO_ALWAYS_INLINE inline void spatial_variance_row_body(ImageSize size, const GeometryWeight& gw,
                                                          const Planes& planes, const float* given, int y) {
    const int w = size.width;
    const Signal& s = planes.ping;
    const float* mask = planes.geometry.mask;
    for (int x0 = 0; x0 < w; x0 += lanes::kWidth<F>) {
        const std::size_t p = static_cast<std::size_t>(y) * w + x0;
        const int lanes_in_row = std::min(lanes::kWidth<F>, w - x0);
        bool all_given = given != nullptr;
        for (int k = 0; k < lanes_in_row && all_given; ++k) all_given = mask[p + k] == 0.0f || given[p + k] >= 0.0f;
        F sw{}, s1{}, s2{};
        if (!all_given) surface_sums<F, true>(size, gw, planes.geometry, s.lum, y, x0, sw, s1, s2);
        for (int k = 0; k < lanes_in_row; ++k) {
            if (mask[p + k] == 0.0f) continue;
            if (given != nullptr && given[p + k] >= 0.0f) {
                s.var[p + k] = given[p + k];
                continue;
            }
            const float mean = s1[k] / sw[k];
            s.var[p + k] = std::max(0.0f, s2[k] / sw[k] - mean * mean);
        }
    }
}

// The mean of `raw` over row y's surface pixels' 5x5 neighbourhood on the same surface, into ping.var.
template <typename F>
MOGAO_ALWAYS_INLINE inline void smoothed_variance_row_body(ImageSize size, const GeometryWeight& gw,
                                                           const Planes& planes, const float* raw, int y) {
    const int w = size.width;
    for (int x0 = 0; x0 < w; x0 += lanes::kWidth<F>) {
        F sw{}, sv{}, unused{};
        surface_sums<F, false>(size, gw, planes.geometry, raw, y, x0, sw, sv, unused);
        const std::size_t p = static_cast<std::size_t>(y) * w + x0;
        for (int k = 0; k < std::min(lanes::kWidth<F>, w - x0); ++k) {
            if (planes.geometry.mask[p + k] != 0.0f) planes.ping.var[p + k] = sv[k] / sw[k];
        }
    }
}

#if MOGAO_HAS_X86_64_V3
using WideLanes = lanes::F8;
#else
using WideLanes = lanes::F4;  // no AVX build: the _v3 functions are never chosen (use_x86_64_v3)
#endif
MOGAO_TARGET_X86_64_V3 void spatial_variance_row_v3(ImageSize size, const GeometryWeight& gw, const Planes& planes,
                                                    const float* given, int y) {
    spatial_variance_row_body<WideLanes>(size, gw, planes, given, y);
}
void spatial_variance_row_base(ImageSize size, const GeometryWeight& gw, const Planes& planes, const float* given,
                               int y) {
    spatial_variance_row_body<lanes::F4>(size, gw, planes, given, y);
}
MOGAO_TARGET_X86_64_V3 void smoothed_variance_row_v3(ImageSize size, const GeometryWeight& gw, const Planes& planes,
                                                     const float* raw, int y) {
    smoothed_variance_row_body<WideLanes>(size, gw, planes, raw, y);
}
void smoothed_variance_row_base(ImageSize size, const GeometryWeight& gw, const Planes& planes, const float* raw,
                                int y) {
    smoothed_variance_row_body<lanes::F4>(size, gw, planes, raw, y);
}

// Luminance variance of each surface pixel from a variance of its colour the caller measured (e.g.
// across a progressive accumulation's passes, progressive_accumulator.h), per channel: demodulated
// like the colour, the channels taken as fully correlated (an upper bound whatever their
// correlation), Var(l) = (Σ_c w_c σ_c / max(a_c, kDemodulationMinAlbedo))², then averaged over the pixel's 5x5
// neighbourhood on the same surface (the geometry weights of the spatial estimate), which steadies an
// estimate from as few as two passes. The pong variance plane is the scratch (filter_level rewrites it).
template <typename Row>
void given_variance(Row smoothed_variance_row, const RgbFloatImage& variance, const GuideBuffers& guides,
                    const GeometryWeight& gw, const Planes& planes, int threads) {
    const ImageSize size = variance.size;
    float* raw = planes.pong.var;
    for (std::size_t i = 0; i < static_cast<std::size_t>(size.pixel_count()); ++i) {
        const float* v = variance.pixels.data() + 3 * i;
        const float* a = guides.albedo.data() + 3 * i;
        const float sd = 0.2126f * std::sqrt(v[0]) / std::max(a[0], kDemodulationMinAlbedo) +
                         0.7152f * std::sqrt(v[1]) / std::max(a[1], kDemodulationMinAlbedo) +
                         0.0722f * std::sqrt(v[2]) / std::max(a[2], kDemodulationMinAlbedo);
        raw[i] = sd * sd;
    }
    for_row_bands(size.height, threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y) smoothed_variance_row(size, gw, planes, raw, y);
    });
}

// colour_scale = 1 / (σ_l sqrt(g3x3(Var)) + ε) [S eq. 5], g3x3 = (1/4, 1/2, 1/4)² over surface pixels,
// for row y, in chunks of pixels as filter_chunk_body (built twice).
template <typename F>
MOGAO_ALWAYS_INLINE inline void colour_scales_row_body(ImageSize size, float sigma_colour, const Signal& s,
                                                       const Planes& planes, int y) {
    using lanes::load;
    constexpr float k[3] = {0.25f, 0.5f, 0.25f};
    constexpr int kW = lanes::kWidth<F>;
    const int w = size.width, h = size.height;
    const float* mask = planes.geometry.mask;
    for (int x0 = 0; x0 < w; x0 += kW) {
        const std::ptrdiff_t p = static_cast<std::ptrdiff_t>(y) * w + x0;
        const F lane_x = lane_columns<F>(x0);
        F sw{}, sv{};
        for (int dy = -1; dy <= 1; ++dy) {
            if (y + dy < 0 || y + dy >= h) continue;
            for (int dx = -1; dx <= 1; ++dx) {
                const std::ptrdiff_t q = p + static_cast<std::ptrdiff_t>(dy) * w + dx;
                const F wt = inside_columns((k[dx + 1] * k[dy + 1]) * load<F>(mask + q), lane_x, x0, dx, w);
                sw += wt;
                sv += wt * load<F>(s.var + q);
            }
        }
        for (int i = 0; i < std::min(kW, w - x0); ++i) {
            const float sd = sw[i] > 0.0f ? std::sqrt(sv[i] / sw[i]) : 0.0f;
            planes.colour_scale[p + i] = sigma_colour > 0.0f ? 1.0f / (sigma_colour * sd + kLuminanceEps) : kHuge;
        }
    }
}
MOGAO_TARGET_X86_64_V3 void colour_scales_row_v3(ImageSize size, float sigma_colour, const Signal& s,
                                                 const Planes& planes, int y) {
    colour_scales_row_body<WideLanes>(size, sigma_colour, s, planes, y);
}
void colour_scales_row_base(ImageSize size, float sigma_colour, const Signal& s, const Planes& planes, int y) {
    colour_scales_row_body<lanes::F4>(size, sigma_colour, s, planes, y);
}

// One à-trous level [D] for the pixels [x0, x0 + W) of row y, W the lanes of F (the last chunk of a
// row may run past its end: those lanes are computed and not stored). Their centre values and
// weighted sums stay in registers while the 25 taps are read: per tap and pixel only the tap's own
// planes are loaded. Built twice (common/cpu_level.h): eight lanes with AVX, four without. A tap row
// outside the image is skipped; a tap column outside it (the row's ends) gets weight 0 lane by lane.
template <typename F>
MOGAO_ALWAYS_INLINE inline void filter_chunk_body(ImageSize size, int step, const GeometryWeight& gw, const Signal& src,
                                                  const Signal& dst, const Planes& planes, int y, int x0) {
    using lanes::abs, lanes::exp_neg, lanes::load, lanes::select, lanes::splat;
    constexpr int kW = lanes::kWidth<F>;
    const int w = size.width, h = size.height;
    const Geometry& g = planes.geometry;
    const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x0);
    const ChunkCentre<F> c(g, gw, p, x0);
    const F lum = load<F>(src.lum + p), cs = load<F>(planes.colour_scale + p);
    F sw{}, sr{}, sg{}, sb{}, sv{};
    for (int ky = -2; ky <= 2; ++ky) {
        const int oy = ky * step;
        if (y + oy < 0 || y + oy >= h) continue;
        for (int kx = -2; kx <= 2; ++kx) {
            const int ox = kx * step;
            const std::ptrdiff_t q = static_cast<std::ptrdiff_t>(p) + static_cast<std::ptrdiff_t>(oy) * w + ox;
            F e = c.geometry_exponent(g, gw, q, static_cast<float>(ox), static_cast<float>(oy)) +
                  abs(lum - load<F>(src.lum + q)) * cs;
            e = select(e < splat<F>(kMaxExponent), e, splat<F>(kMaxExponent));  // inf and NaN (sky p) give the limit
            const F wt =
                inside_columns((kB3[kx + 2] * kB3[ky + 2]) * load<F>(g.mask + q) * exp_neg(e), c.lane_x, x0, ox, w);
            sw += wt;
            sr += wt * load<F>(src.r + q);
            sg += wt * load<F>(src.g + q);
            sb += wt * load<F>(src.b + q);
            sv += wt * wt * load<F>(src.var + q);
        }
    }
    const int lanes_in_row = std::min(kW, w - x0);
    for (int k = 0; k < lanes_in_row; ++k) {
        const std::size_t i = p + static_cast<std::size_t>(k);
        if (g.mask[i] == 0.0f) {
            dst.r[i] = src.r[i], dst.g[i] = src.g[i], dst.b[i] = src.b[i], dst.var[i] = 0.0f;
            dst.lum[i] = src.lum[i];
            continue;
        }
        const float inv = 1.0f / sw[k];
        dst.r[i] = sr[k] * inv, dst.g[i] = sg[k] * inv, dst.b[i] = sb[k] * inv;
        dst.var[i] = sv[k] * inv * inv;
        dst.lum[i] = luminance(dst.r[i], dst.g[i], dst.b[i]);
    }
}
MOGAO_TARGET_X86_64_V3 void filter_row_v3(ImageSize size, int step, const GeometryWeight& gw, const Signal& src,
                                          const Signal& dst, const Planes& planes, int y) {
    for (int x0 = 0; x0 < size.width; x0 += lanes::kWidth<WideLanes>)
        filter_chunk_body<WideLanes>(size, step, gw, src, dst, planes, y, x0);
}
void filter_row_base(ImageSize size, int step, const GeometryWeight& gw, const Signal& src, const Signal& dst,
                     const Planes& planes, int y) {
    for (int x0 = 0; x0 < size.width; x0 += lanes::kWidth<lanes::F4>)
        filter_chunk_body<lanes::F4>(size, step, gw, src, dst, planes, y, x0);
}

// The build of the tap loops this run uses.
struct Kernels {
    decltype(&spatial_variance_row_base) spatial_variance_row;
    decltype(&smoothed_variance_row_base) smoothed_variance_row;
    decltype(&colour_scales_row_base) colour_scales_row;
    decltype(&filter_row_base) filter_row;
};

Kernels kernels_for(CpuLevel level) {
    if (use_x86_64_v3(level))
        return {spatial_variance_row_v3, smoothed_variance_row_v3, colour_scales_row_v3, filter_row_v3};
    return {spatial_variance_row_base, smoothed_variance_row_base, colour_scales_row_base, filter_row_base};
}

// One à-trous level [D]: every surface pixel becomes the weighted mean of its 5x5 taps at `step`.
void filter_level(const Kernels& kernels, ImageSize size, int step, const GeometryWeight& gw, const Signal& src,
                  const Signal& dst, const Planes& planes, int threads) {
    for_row_bands(size.height, threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y) kernels.filter_row(size, step, gw, src, dst, planes, y);
    });
}

}  // namespace

Status AtrousDenoiser::run(const RgbFloatImage& noisy, const GuideBuffers& guides, const AtrousParams& params,
                           RgbFloatImage& out, const RgbFloatImage* variance,
                           const std::vector<float>* luminance_variance) {
    if (Status s = validate_denoise_input(noisy, guides, params); !s.ok()) return s;
    if (variance) {
        if (Status s = check_variance(*variance, noisy.size); !s.ok()) return s;
    }
    if (luminance_variance) {
        if (Status s = check_luminance_variance(*luminance_variance, noisy.size, variance != nullptr); !s.ok())
            return s;
    }
    if (params.iterations == 0) {
        out = noisy;
        return {};
    }
    const ImageSize size = noisy.size;
    const auto n = static_cast<std::size_t>(size.pixel_count());
    const int threads =
        params.threads > 0 ? params.threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
    Planes planes = make_planes(planes_, n);
    const GeometryWeight gw = make_geometry_weight(params);
    const Kernels kernels = kernels_for(params.cpu);
    prepare(noisy, guides, planes, threads);
    if (variance) {
        given_variance(kernels.smoothed_variance_row, *variance, guides, gw, planes, threads);
    } else {
        const float* given = luminance_variance ? luminance_variance->data() : nullptr;
        for_row_bands(size.height, threads, [&](int y0, int y1) {
            for (int y = y0; y < y1; ++y) kernels.spatial_variance_row(size, gw, planes, given, y);
        });
    }
    for (int level = 0; level < params.iterations; ++level) {
        for_row_bands(size.height, threads, [&](int y0, int y1) {
            for (int y = y0; y < y1; ++y) kernels.colour_scales_row(size, params.sigma_colour, planes.ping, planes, y);
        });
        filter_level(kernels, size, 1 << level, gw, planes.ping, planes.pong, planes, threads);
        std::swap(planes.ping, planes.pong);
    }
    out.size = size;
    out.pixels.resize(3 * n);
    const Signal& s = planes.ping;
    for (std::size_t i = 0; i < n; ++i) {
        float* o = out.pixels.data() + 3 * i;
        const bool hit = guides.hit[i] != 0;
        const float* a = guides.albedo.data() + 3 * i;
        o[0] = hit ? s.r[i] * std::max(a[0], kDemodulationMinAlbedo) : s.r[i];
        o[1] = hit ? s.g[i] * std::max(a[1], kDemodulationMinAlbedo) : s.g[i];
        o[2] = hit ? s.b[i] * std::max(a[2], kDemodulationMinAlbedo) : s.b[i];
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
