// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/denoise/temporal_accumulation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <thread>

#include "renderfarm/denoise/atrous_filter.h"

namespace mogao {
namespace {

void check_sizes(const RgbFloatImage& current, const GuideBuffers& guides, const CameraSetup& camera) {
    if (guides.size != current.size || camera.size != current.size)
        throw std::invalid_argument("temporal accumulation: the frame is " + std::to_string(current.size.width) + "x" +
                                    std::to_string(current.size.height) + ", its guides " +
                                    std::to_string(guides.size.width) + "x" + std::to_string(guides.size.height) +
                                    " and its camera " + std::to_string(camera.size.width) + "x" +
                                    std::to_string(camera.size.height));
}

Eigen::Vector3f at3(const std::vector<float>& v, std::size_t i) { return {v[3 * i], v[3 * i + 1], v[3 * i + 2]}; }

// What pixel i's channel c is divided by to demodulate it.
float demodulation(const GuideBuffers& guides, std::size_t i, std::size_t c) {
    return std::max(guides.albedo[3 * i + c], kDemodulationMinAlbedo);
}

float luminance(const Eigen::Vector3f& c) { return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]; }

}  // namespace

void check_temporal_params(const TemporalParams& params) {
    if (!(params.alpha > 0.0f && params.alpha <= 1.0f))
        throw std::invalid_argument("temporal accumulation: alpha must be in (0, 1], is " +
                                    std::to_string(params.alpha));
    if (!(params.plane_tolerance > 0.0f && std::isfinite(params.plane_tolerance)))
        throw std::invalid_argument("temporal accumulation: plane_tolerance must be > 0");
    if (!(params.normal_min_cos >= -1.0f && params.normal_min_cos <= 1.0f))
        throw std::invalid_argument("temporal accumulation: normal_min_cos must be in [-1, 1]");
}

bool TemporalHistory::gather(const Pass& f, const Eigen::Vector3f& position, const Eigen::Vector3f& normal, float depth,
                             float px, float py, Eigen::Vector3f& value, float& length, Moments& moments) const {
    const TemporalParams& params = f.params;
    const float fx = px - 0.5f;
    const float fy = py - 0.5f;
    // Only between the previous frame's pixel centres: beyond them a value would be extrapolated
    // from the border pixel, and carried on from frame to frame it drifts with the motion.
    if (!(fx >= 0.0f && fy >= 0.0f && fx <= static_cast<float>(camera_.size.width - 1) &&
          fy <= static_cast<float>(camera_.size.height - 1)))
        return false;
    const int x0 = static_cast<int>(fx);  // fx >= 0: truncation is floor
    const int y0 = static_cast<int>(fy);
    const float wx = fx - static_cast<float>(x0);
    const float wy = fy - static_cast<float>(y0);
    const float tolerance = params.plane_tolerance * depth;
    float weight = 0.0f;
    int accepted = 0;
    value = Eigen::Vector3f::Zero();
    length = 0.0f;
    moments = {};
    for (int k = 0; k < 4; ++k) {
        const int x = std::min(x0 + (k & 1), camera_.size.width - 1);  // x0 = W - 1 only where wx = 0
        const int y = std::min(y0 + (k >> 1), camera_.size.height - 1);
        const std::size_t i =
            static_cast<std::size_t>(y) * static_cast<std::size_t>(camera_.size.width) + static_cast<std::size_t>(x);
        if (hit_[i] == 0) continue;
        const Eigen::Vector3f n = at3(normal_, i);
        if (n.dot(normal) < params.normal_min_cos) continue;
        if (std::abs(n.dot(position) - plane_[i]) > tolerance) continue;  // |n'·(P − P')|
        const float w = ((k & 1) != 0 ? wx : 1.0f - wx) * ((k >> 1) != 0 ? wy : 1.0f - wy);
        value += w * at3(illumination_, i);
        length += w * length_[i];
        moments.m1 += w * moments_[3 * i];
        moments.m2 += w * moments_[3 * i + 1];
        moments.factor += w * w * moments_[3 * i + 2];
        weight += w;
        ++accepted;
    }
    if (!(weight > 1e-3f)) return false;
    value /= weight;
    length /= weight;
    moments.m1 /= weight, moments.m2 /= weight, moments.factor /= weight * weight;
    if (params.sharp_history && accepted == 4) sharpen(fx, fy, value);
    return true;
}

// The history at (fx, fy) by Catmull-Rom interpolation of the 4x4 previous pixels around it, once
// gather() accepted all of the central 2x2, clamped per channel to their range. The outer twelve
// taps are not tested: their weights are at most 0, so another surface there can only steepen the
// curve, and the clamp bounds it (testing them cost more than the rest of the blend). Near the
// image's border `value` stays bilinear.
// Bilinear resampling, repeated frame after frame as the view moves, low-pass filters the history
// (about a quarter of a pixel of blur per frame at half-pixel offsets); the cubic keeps it sharp.
// The usual history filter of temporal anti-aliasing (Karis, "High-Quality Temporal
// Supersampling", SIGGRAPH 2014 course).
void TemporalHistory::sharpen(float fx, float fy, Eigen::Vector3f& value) const {
    const int x0 = static_cast<int>(std::floor(fx));
    const int y0 = static_cast<int>(std::floor(fy));
    if (x0 < 1 || y0 < 1 || x0 + 2 >= camera_.size.width || y0 + 2 >= camera_.size.height) return;
    const auto weights = [](float t) {
        return std::array<float, 4>{t * (-0.5f + t * (1.0f - 0.5f * t)), 1.0f + t * t * (-2.5f + 1.5f * t),
                                    t * (0.5f + t * (2.0f - 1.5f * t)), t * t * (-0.5f + 0.5f * t)};
    };
    const std::array<float, 4> wx = weights(fx - static_cast<float>(x0));
    const std::array<float, 4> wy = weights(fy - static_cast<float>(y0));
    // Rows of three interleaved channels, no branch per tap: this runs for most pixels of a moving frame.
    const auto width = static_cast<std::size_t>(camera_.size.width);
    const float* top_left =
        &illumination_[3 * (static_cast<std::size_t>(y0 - 1) * width + static_cast<std::size_t>(x0 - 1))];
    const float* centre = top_left + 3 * width + 3;  // (x0, y0); the next row's is centre + 3 * width
    for (std::size_t c = 0; c < 3; ++c) {
        float sum = 0.0f;
        for (std::size_t j = 0; j < 4; ++j) {
            const float* row = top_left + 3 * j * width + c;
            sum += wy[j] * (wx[0] * row[0] + wx[1] * row[3] + wx[2] * row[6] + wx[3] * row[9]);
        }
        const float* below = centre + 3 * width;
        const float lo = std::min(std::min(centre[c], centre[3 + c]), std::min(below[c], below[3 + c]));
        const float hi = std::max(std::max(centre[c], centre[3 + c]), std::max(below[c], below[3 + c]));
        value[static_cast<Eigen::Index>(c)] = std::clamp(sum, lo, hi);
    }
}

// Hole i's illumination from the pixels within `radius` that are not holes: the mean of those on its surface (the
// history's tests: normal_min_cos, plane_tolerance), weighted by 1 / (1 + distance²), or of any surface pixel when
// none is. False when there is none.
bool TemporalHistory::neighbour_fill(const Pass& f, std::size_t i, int radius, Eigen::Vector3f& value) {
    const int width = f.current.size.width;
    const int height = f.current.size.height;
    const int x = static_cast<int>(i % static_cast<std::size_t>(width));
    const int y = static_cast<int>(i / static_cast<std::size_t>(width));
    const Eigen::Vector3f p = at3(f.position, i);
    const Eigen::Vector3f n = at3(f.guides.normal, i);
    Eigen::Vector3f same = Eigen::Vector3f::Zero(), any = Eigen::Vector3f::Zero();
    float same_w = 0.0f, any_w = 0.0f;
    for (int qy = std::max(0, y - radius); qy <= std::min(height - 1, y + radius); ++qy) {
        for (int qx = std::max(0, x - radius); qx <= std::min(width - 1, x + radius); ++qx) {
            const std::size_t j = f.guides.pixel(qx, qy);
            if (f.guides.hit[j] == 0 || f.illumination[3 * j] < 0.0f) continue;
            const float w = 1.0f / float(1 + (qx - x) * (qx - x) + (qy - y) * (qy - y));
            const Eigen::Vector3f v = at3(f.illumination, j);
            any += w * v, any_w += w;
            if (at3(f.guides.normal, j).dot(n) < f.params.normal_min_cos ||
                std::abs(n.dot(p - at3(f.position, j))) > f.params.plane_tolerance * f.guides.depth[i])
                continue;
            same += w * v, same_w += w;
        }
    }
    if (!(any_w > 0.0f)) return false;
    value = same_w > 0.0f ? Eigen::Vector3f(same / same_w) : Eigen::Vector3f(any / any_w);
    return true;
}

// The unshaded pixels no history covers (disoccluded, or new at the image's edge) from their neighbours in the same
// frame (neighbour_fill): within 2 pixels, where the sparse pattern always has a shaded one (view_request.h); farther
// where a frame cut at its budget copied an unshaded pixel over a whole block (tile_pass.h); 0 where no surface pixel
// is within 32. Length 0: the pixel's first shaded sample replaces the fill. Reads only pixels that are not holes,
// so the result does not depend on the order.
std::size_t TemporalHistory::fill_holes(const Pass& f) {
    std::vector<std::size_t> holes;
    for (std::size_t i = 0; i < f.guides.hit.size(); ++i)
        if (f.guides.hit[i] != 0 && f.illumination[3 * i] < 0.0f) holes.push_back(i);
    std::vector<Eigen::Vector3f> filled(holes.size(), Eigen::Vector3f::Zero());
    for (std::size_t h = 0; h < holes.size(); ++h) {
        for (const int radius : {2, 8, 32})
            if (neighbour_fill(f, holes[h], radius, filled[h])) break;
    }
    for (std::size_t h = 0; h < holes.size(); ++h) {
        set_pixel(f, holes[h], filled[h]);
        // Moments of the fill itself (no spread): a neighbour that resamples the hole next frame reads
        // the light it shows, not a second moment of 0 beside a first moment of that light.
        const float l = luminance(filled[h]);
        set_moments(f, holes[h], {l, l * l, 1.0f}, 0.0f);
    }
    return holes.size();
}

// Pixel i's moments become `m`, its length `length`, and its luminance variance follows from them
// (the header's formula).
void TemporalHistory::set_moments(const Pass& f, std::size_t i, Moments m, float length) {
    f.length[i] = length;
    const float spread = m.m2 - m.m1 * m.m1;
    if (!std::isfinite(spread)) {
        // A non-finite sample (a NaN, a square past float's range): the pixel starts again rather than
        // carry it on for good, and is left to the spatial estimate (which reads such samples as 0),
        // not given a variance of 0 (max(0, NaN)) or one the filter refuses.
        m = {};
        length = 0.0f;  // the next shaded sample replaces the pixel (a = 1)
        f.length[i] = length;
        f.luminance_variance[i] = -1.0f;
        // Nor does the illumination keep it (0 · NaN is NaN even at a = 1): this frame's output has it,
        // as before; the history does not.
        for (std::size_t c = 0; c < 3; ++c) f.illumination[3 * i + c] = 0.0f;
    } else {
        f.luminance_variance[i] = length >= kMinMomentsFrames ? std::max(0.0f, spread) * m.factor : -1.0f;
    }
    f.moments[3 * i] = m.m1;
    f.moments[3 * i + 1] = m.m2;
    f.moments[3 * i + 2] = m.factor;
}

// Pixel i's illumination becomes `value` and its output value ⊙ its albedo (re-modulated).
void TemporalHistory::set_pixel(const Pass& f, std::size_t i, const Eigen::Vector3f& value) {
    const int width = f.current.size.width;
    float* o = f.out.at(static_cast<int>(i % static_cast<std::size_t>(width)),
                        static_cast<int>(i / static_cast<std::size_t>(width)));
    for (std::size_t c = 0; c < 3; ++c) {
        f.illumination[3 * i + c] = value[static_cast<Eigen::Index>(c)];
        o[c] = value[static_cast<Eigen::Index>(c)] * demodulation(f.guides, i, c);
    }
}

// Rows [y0, y1) of accumulate(): writes their pixels of out, illumination, position, plane,
// length, moments and luminance variance; counts them. A pixel that no history covers keeps its own radiance, bit for
// bit. Each row's points and their positions in the previous image are computed first, a row at a time
// (PixelCentreRays::points_row, FrameProjection::project_row: vectorised), then each pixel's taps.
void TemporalHistory::accumulate_rows(const Pass& f, int y0, int y1, TemporalStats& result) const {
    // Counted here and stored once at the end: the threads' results sit side by side in one cache line, and
    // incrementing them in place at every pixel made the cores fight over it.
    TemporalStats counted;
    const int width = f.current.size.width;
    const auto w = static_cast<std::size_t>(width);
    std::vector<float> px(w), py(w), pz(w), hx(w), hy(w);
    std::vector<std::uint8_t> in_view(w, 0);
    for (int y = y0; y < y1; ++y) {
        const std::size_t row = f.guides.pixel(0, y);
        f.rays.points_row(y, &f.guides.depth[row], width, px.data(), py.data(), pz.data());
        if (!empty())
            f.to_history.project_row(px.data(), py.data(), pz.data(), width, hx.data(), hy.data(), in_view.data());
        for (int x = 0; x < width; ++x) {
            const std::size_t i = row + static_cast<std::size_t>(x);
            if (f.guides.hit[i] == 0) {  // the buffers are reused: zero what a sky pixel leaves (sharpen reads it)
                for (std::size_t c = 0; c < 3; ++c) f.illumination[3 * i + c] = f.position[3 * i + c] = 0.0f;
                f.plane[i] = f.length[i] = f.luminance_variance[i] = 0.0f;
                for (std::size_t k = 0; k < 3; ++k) f.moments[3 * i + k] = 0.0f;
                continue;
            }
            ++counted.surface_pixels;
            const auto xs = static_cast<std::size_t>(x);
            const Eigen::Vector3f p(px[xs], py[xs], pz[xs]);
            const Eigen::Vector3f normal = at3(f.guides.normal, i);
            for (int c = 0; c < 3; ++c) f.position[3 * i + static_cast<std::size_t>(c)] = p[c];
            f.plane[i] = normal.dot(p);
            const float* own = f.current.at(x, y);
            const bool shaded = !(own[0] < 0.0f);  // kUnshadedRadiance: a sparse frame's unshaded pixel
            if (!shaded) ++counted.unshaded;
            Eigen::Vector3f illumination(kUnshadedRadiance, 0.0f, 0.0f);  // a hole until fill_holes()
            if (shaded) {
                for (std::size_t c = 0; c < 3; ++c)
                    illumination[static_cast<Eigen::Index>(c)] = own[c] / demodulation(f.guides, i, c);
            }
            for (int c = 0; c < 3; ++c) f.illumination[3 * i + static_cast<std::size_t>(c)] = illumination[c];
            Eigen::Vector3f history;
            float frames = 0.0f;
            Moments moments;
            const float l = shaded ? luminance(illumination) : 0.0f;
            if (empty() || in_view[xs] == 0 ||
                !gather(f, p, normal, f.guides.depth[i], hx[xs], hy[xs], history, frames, moments)) {
                set_moments(f, i, {l, l * l, 1.0f}, shaded ? 1.0f : 0.0f);  // a hole's are set by fill_holes()
                continue;
            }
            ++counted.reprojected;
            if (!shaded) {  // the history alone, still as many frames as it had
                set_pixel(f, i, history);
                set_moments(f, i, moments, frames);
                continue;
            }
            const float a = std::max(f.alpha, 1.0f / (frames + 1.0f));
            set_pixel(f, i, (1.0f - a) * history + a * illumination);
            const float b = 1.0f - a;
            set_moments(f, i, {b * moments.m1 + a * l, b * moments.m2 + a * l * l, b * b * moments.factor + a * a},
                        frames + 1.0f);
        }
    }
    result = counted;
}

RgbFloatImage TemporalHistory::accumulate(const RgbFloatImage& current, const GuideBuffers& guides,
                                          const CameraSetup& camera, const TemporalParams& params, TemporalStats* stats,
                                          int shading_one_in) {
    check_temporal_params(params);
    check_sizes(current, guides, camera);
    if (shading_one_in < 1)
        throw std::invalid_argument("temporal accumulation: shading_one_in must be >= 1, is " +
                                    std::to_string(shading_one_in));
    const auto n = static_cast<std::size_t>(current.size.pixel_count());
    RgbFloatImage out = current;
    next_illumination_.resize(3 * n);
    position_.resize(3 * n);
    next_plane_.resize(n);
    next_length_.resize(n);
    next_moments_.resize(3 * n);
    luminance_variance_.resize(n);
    const float alpha = 1.0f - std::pow(1.0f - params.alpha, static_cast<float>(shading_one_in));
    const Pass f{current,
                 guides,
                 PixelCentreRays(camera),
                 FrameProjection(empty() ? camera : camera_),
                 params,
                 alpha,
                 out,
                 next_illumination_,
                 position_,
                 next_plane_,
                 next_length_,
                 next_moments_,
                 luminance_variance_};
    // Rows split over the cores (each pixel reads only the history and writes only itself, so the
    // result does not depend on the split): the admin runs this while the ranks wait.
    const int height = current.size.height;
    const int threads = std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1, std::max(1, height / 16));
    std::vector<TemporalStats> counted(static_cast<std::size_t>(threads));
    std::vector<std::thread> workers;
    for (int t = 1; t < threads; ++t) {
        workers.emplace_back([&, t] {
            accumulate_rows(f, height * t / threads, height * (t + 1) / threads, counted[static_cast<std::size_t>(t)]);
        });
    }
    accumulate_rows(f, 0, height / threads, counted[0]);
    for (std::thread& w : workers) w.join();
    TemporalStats total;
    for (const TemporalStats& c : counted) {
        total.surface_pixels += c.surface_pixels;
        total.reprojected += c.reprojected;
        total.unshaded += c.unshaded;
    }
    total.filled = fill_holes(f);
    camera_ = camera;
    illumination_.swap(next_illumination_);
    plane_.swap(next_plane_);
    normal_ = guides.normal;  // copy assignment keeps the storage of a size already seen
    hit_ = guides.hit;
    length_.swap(next_length_);
    moments_.swap(next_moments_);
    if (stats != nullptr) *stats = total;
    return out;
}

void TemporalHistory::clear() {
    illumination_.clear();
    plane_.clear();
    normal_.clear();
    hit_.clear();
    length_.clear();
    moments_.clear();
    luminance_variance_.clear();
}

}  // namespace mogao
