// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/trace/integrator.h"

#include <algorithm>
#include <limits>
#include <numbers>

#include <embree3/rtcore.h>

#include "renderfarm/trace/ray_offset.h"
#include "renderfarm/trace/sampling.h"
#include "renderfarm/trace/sobol.h"

namespace mogao {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();
constexpr float kShadowEnd = 0.999f;  // fraction of the distance to a point/area light

RTCRay make_ray(const Eigen::Vector3f& org, const Eigen::Vector3f& dir, float tfar) {
    RTCRay ray{};
    ray.org_x = org.x();
    ray.org_y = org.y();
    ray.org_z = org.z();
    ray.tnear = 0.0f;  // the origin is already offset (ray_offset.h)
    ray.dir_x = dir.x();
    ray.dir_y = dir.y();
    ray.dir_z = dir.z();
    ray.time = 0.0f;
    ray.tfar = tfar;
    ray.mask = 0xFFFFFFFFu;
    ray.flags = 0;
    return ray;
}

bool occluded(RTCScene scene, const Eigen::Vector3f& org, const Eigen::Vector3f& dir, float tfar,
              std::uint64_t& rays) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    RTCRay ray = make_ray(org, dir, tfar);
    rtcOccluded1(scene, &context, &ray);
    ++rays;
    return ray.tfar < 0.0f;  // Embree sets tfar = -inf on any hit
}

struct Vertex {
    const SurfaceHit& hit;
    const ShadingMaterial& material;  // with the hit's tint applied (tinted_material)
    const Eigen::Vector3f& wo;
    Eigen::Vector3f origin;  // offset along the geometric normal, for rays leaving on its side
};

// f(wi) cosθ for a direction above both normals, 0 otherwise.
Eigen::Vector3f reflect_factor(const Vertex& x, const Eigen::Vector3f& wi) {
    const float cos_shading = x.hit.shading_normal.dot(wi);
    if (cos_shading <= 0.0f || x.hit.geometric_normal.dot(wi) <= 0.0f) return Eigen::Vector3f::Zero();
    return eval_brdf(x.material, x.hit.shading_normal, x.wo, wi) * cos_shading;
}

// Environment: (1/N) Σ π f(wo, w) V(w) L_env over N = max(1, ao_samples) cosine-weighted
// directions (pdf cosθ/π), so f cosθ / pdf = π f. See integrator.h for why N >= 1.
Eigen::Vector3f environment_light(const FrameContext& frame, const Vertex& x, PixelSampler& sampler,
                                  std::uint64_t& rays) {
    const int count = std::max(1, frame.ao_samples);
    const PixelSampler::Pair pair = sampler.take();
    const Frame tangent(x.hit.shading_normal);
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();
    for (int s = 0; s < count; ++s) {
        const Eigen::Vector2f u = pair.point(s, count);
        const Eigen::Vector3f w = cosine_hemisphere(tangent, u.x(), u.y());
        if (x.hit.geometric_normal.dot(w) <= 0.0f) continue;  // into the surface itself
        if (occluded(frame.scene->root(), x.origin, w, kInfinity, rays)) continue;
        sum += eval_brdf(x.material, x.hit.shading_normal, x.wo, w);
    }
    return sum.cwiseProduct(frame.lights->environment) * (std::numbers::pi_v<float> / static_cast<float>(count));
}

Eigen::Vector3f direct_light(const FrameContext& frame, const Vertex& x, PixelSampler& sampler, std::uint64_t& rays) {
    const LightSet& lights = *frame.lights;
    const RTCScene scene = frame.scene->root();
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();
    for (const PreparedDirectional& l : lights.directional) {
        const Eigen::Vector3f f = reflect_factor(x, l.to_light);
        if (f.isZero()) continue;
        if (l.cast_shadows && occluded(scene, x.origin, l.to_light, kInfinity, rays)) continue;
        sum += f.cwiseProduct(l.irradiance);
    }
    for (const PreparedPoint& l : lights.point) {
        const Eigen::Vector3f to_light = l.position - x.hit.position;
        const float distance2 = to_light.squaredNorm();
        if (!(distance2 > 0.0f)) continue;
        const float distance = std::sqrt(distance2);
        const Eigen::Vector3f wi = to_light / distance;
        const Eigen::Vector3f f = reflect_factor(x, wi);
        if (f.isZero()) continue;
        if (l.cast_shadows && occluded(scene, x.origin, wi, kShadowEnd * distance, rays)) continue;
        sum += f.cwiseProduct(l.intensity) / distance2;
    }
    if (!lights.area.empty()) {
        const float weight = 1.0f / static_cast<float>(frame.area_light_samples);
        for (const PreparedArea& l : lights.area) {
            const PixelSampler::Pair pair = sampler.take();
            for (int s = 0; s < frame.area_light_samples; ++s) {
                const Eigen::Vector2f u = pair.point(s, frame.area_light_samples);
                const Eigen::Vector3f to_light = l.corner + u.x() * l.edge_u + u.y() * l.edge_v - x.hit.position;
                const float distance2 = to_light.squaredNorm();
                if (!(distance2 > 0.0f)) continue;
                const float distance = std::sqrt(distance2);
                const Eigen::Vector3f wi = to_light / distance;
                const float cos_light = -l.normal.dot(wi);
                if (cos_light <= 0.0f) continue;  // one-sided emitter seen from behind
                const Eigen::Vector3f f = reflect_factor(x, wi);
                if (f.isZero()) continue;
                if (l.cast_shadows && occluded(scene, x.origin, wi, kShadowEnd * distance, rays)) continue;
                sum += f.cwiseProduct(l.radiance) * (weight * cos_light * l.area / distance2);
            }
        }
    }
    if (lights.has_environment) sum += environment_light(frame, x, sampler, rays);
    return sum;
}

}  // namespace

Eigen::Vector3f radiance_at(const FrameContext& frame, const SurfaceHit& first, const Eigen::Vector3f& first_wo,
                            PixelSampler& sampler, std::uint64_t& rays) {
    Eigen::Vector3f radiance = Eigen::Vector3f::Zero();
    Eigen::Vector3f throughput = Eigen::Vector3f::Ones();
    SurfaceHit hit = first;
    Eigen::Vector3f wo = first_wo;
    for (int depth = 0;; ++depth) {
        const ShadingMaterial& base = (*frame.materials)[hit.material];
        ShadingMaterial tinted;
        if (hit.tinted) tinted = tinted_material(base, hit.tint);  // untinted meshes skip the copy
        const ShadingMaterial& material = hit.tinted ? tinted : base;
        const Vertex x{hit, material, wo, offset_ray_origin(hit.position, hit.geometric_normal)};
        radiance += throughput.cwiseProduct(direct_light(frame, x, sampler, rays));
        if (depth == frame.max_bounces) break;

        const Eigen::Vector2f u = sampler.next2d();
        const Eigen::Vector3f wi = cosine_hemisphere(Frame(hit.shading_normal), u.x(), u.y());
        if (hit.geometric_normal.dot(wi) <= 0.0f) break;
        // f cosθ / pdf with pdf = cosθ/π (PBRT 4th ed. §13.1).
        throughput =
            throughput.cwiseProduct(eval_brdf(material, hit.shading_normal, wo, wi)) * std::numbers::pi_v<float>;
        if (!(throughput.maxCoeff() > 0.0f)) break;

        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
        RTCRayHit ray_hit{};
        ray_hit.ray = make_ray(x.origin, wi, kInfinity);
        ray_hit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        ray_hit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(frame.scene->root(), &context, &ray_hit);
        ++rays;
        if (ray_hit.hit.geomID == RTC_INVALID_GEOMETRY_ID) break;  // escaped: see header
        hit = frame.scene->surface(x.origin, wi, ray_hit.ray.tfar, ray_hit.hit.instID[0], ray_hit.hit.primID,
                                   ray_hit.hit.u, ray_hit.hit.v,
                                   Eigen::Vector3f(ray_hit.hit.Ng_x, ray_hit.hit.Ng_y, ray_hit.hit.Ng_z));
        wo = -wi;
    }
    return radiance;
}

}  // namespace mogao
