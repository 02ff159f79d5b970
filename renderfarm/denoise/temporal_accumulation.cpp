// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/denoise/temporal_accumulation.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <thread>

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

bool TemporalHistory::gather(const Eigen::Vector3f& position, const Eigen::Vector3f& normal, float depth,
                             const TemporalParams& params, Eigen::Vector3f& value, float& length) const {
    double px = 0.0;
    double py = 0.0;
    if (!project_to_image(camera_, position.cast<double>(), px, py)) return false;
    const double fx = px - 0.5;
    const double fy = py - 0.5;
    if (!(fx > -1.0 && fy > -1.0 && fx < camera_.size.width && fy < camera_.size.height)) return false;
    const int x0 = static_cast<int>(std::floor(fx));
    const int y0 = static_cast<int>(std::floor(fy));
    const auto wx = static_cast<float>(fx - x0);
    const auto wy = static_cast<float>(fy - y0);
    float weight = 0.0f;
    value = Eigen::Vector3f::Zero();
    length = 0.0f;
    for (int k = 0; k < 4; ++k) {
        const int x = x0 + (k & 1);
        const int y = y0 + (k >> 1);
        if (x < 0 || y < 0 || x >= camera_.size.width || y >= camera_.size.height) continue;
        const std::size_t i =
            static_cast<std::size_t>(y) * static_cast<std::size_t>(camera_.size.width) + static_cast<std::size_t>(x);
        if (hit_[i] == 0) continue;
        const Eigen::Vector3f n = at3(normal_, i);
        if (n.dot(normal) < params.normal_min_cos) continue;
        if (std::abs(n.dot(position - at3(position_, i))) > params.plane_tolerance * depth) continue;
        const float w = ((k & 1) != 0 ? wx : 1.0f - wx) * ((k >> 1) != 0 ? wy : 1.0f - wy);
        value += w * Eigen::Vector3f(radiance_.at(x, y)[0], radiance_.at(x, y)[1], radiance_.at(x, y)[2]);
        length += w * length_[i];
        weight += w;
    }
    if (!(weight > 1e-3f)) return false;
    value /= weight;
    length /= weight;
    return true;
}

// Rows [y0, y1) of accumulate(): writes their pixels of out, position and length; counts them.
void TemporalHistory::accumulate_rows(const Pass& f, int y0, int y1, TemporalStats& counted) const {
    for (int y = y0; y < y1; ++y) {
        for (int x = 0; x < f.current.size.width; ++x) {
            const std::size_t i = f.guides.pixel(x, y);
            if (f.guides.hit[i] == 0) continue;
            ++counted.surface_pixels;
            const Ray ray = generate_column_ray(f.camera, f.columns, x, y + 0.5);
            const Eigen::Vector3f p =
                (ray.origin + static_cast<double>(f.guides.depth[i]) * ray.direction).cast<float>();
            for (int c = 0; c < 3; ++c) f.position[3 * i + static_cast<std::size_t>(c)] = p[c];
            Eigen::Vector3f history;
            float frames = 0.0f;
            if (empty() || !gather(p, at3(f.guides.normal, i), f.guides.depth[i], f.params, history, frames)) {
                f.length[i] = 1.0f;
                continue;
            }
            ++counted.reprojected;
            const float a = std::max(f.params.alpha, 1.0f / (frames + 1.0f));
            float* o = f.out.at(x, y);
            for (int c = 0; c < 3; ++c) o[c] = (1.0f - a) * history[c] + a * o[c];
            f.length[i] = frames + 1.0f;
        }
    }
}

RgbFloatImage TemporalHistory::accumulate(const RgbFloatImage& current, const GuideBuffers& guides,
                                          const CameraSetup& camera, const TemporalParams& params,
                                          TemporalStats* stats) {
    check_temporal_params(params);
    check_sizes(current, guides, camera);
    const auto n = static_cast<std::size_t>(current.size.pixel_count());
    RgbFloatImage out = current;
    std::vector<float> position(3 * n, 0.0f);
    std::vector<float> length(n, 0.0f);
    const Pass f{current, guides, camera, make_cylinder_columns(camera), params, out, position, length};
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
    }
    camera_ = camera;
    radiance_ = out;
    position_ = std::move(position);
    normal_ = guides.normal;
    hit_ = guides.hit;
    length_ = std::move(length);
    if (stats != nullptr) *stats = total;
    return out;
}

void TemporalHistory::clear() {
    radiance_ = {};
    position_.clear();
    normal_.clear();
    hit_.clear();
    length_.clear();
}

}  // namespace mogao
