// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/trace/integrator.h"

#include <algorithm>
#include <limits>
#include <numbers>

#include <embree3/rtcore.h>

#include "renderfarm/trace/light_selection.h"
#include "renderfarm/trace/ray_offset.h"
#include "renderfarm/trace/sampling.h"
#include "renderfarm/trace/sobol.h"

namespace mogao {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();
constexpr float kShadowEnd = 0.999f;  // fraction of the distance to a point/area light
constexpr int kMaxQueryGroup = 62;    // lights beyond share one packet group (packet_integrator.cpp)

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

// Appends a single ray to the log, sixteen to a RecordedPacket (replayed ray by ray).
void record_single(RecordedRays* log, const Eigen::Vector3f& org, const Eigen::Vector3f& dir, float tfar,
                   bool occlusion) {
    if (log == nullptr) return;
    if (log->packets.empty() || log->packets.back().packet || log->packets.back().occlusion != occlusion ||
        log->packets.back().valid[RecordedPacket::kLanes - 1] != 0) {
        log->packets.emplace_back();
        log->packets.back().packet = false;
        log->packets.back().occlusion = occlusion;
    }
    RecordedPacket& p = log->packets.back();
    std::size_t l = 0;
    while (p.valid[l] != 0) ++l;
    p.valid[l] = -1;
    p.org_x[l] = org.x();
    p.org_y[l] = org.y();
    p.org_z[l] = org.z();
    p.dir_x[l] = dir.x();
    p.dir_y[l] = dir.y();
    p.dir_z[l] = dir.z();
    p.tfar[l] = tfar;
}

bool occluded(RTCScene scene, const Eigen::Vector3f& org, const Eigen::Vector3f& dir, float tfar, std::uint64_t& rays,
              RecordedRays* log) {
    record_single(log, org, dir, tfar, true);
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    RTCRay ray = make_ray(org, dir, tfar);
    rtcOccluded1(scene, &context, &ray);
    ++rays;
    return ray.tfar < 0.0f;  // Embree sets tfar = -inf on any hit
}

// f(wi) cosθ for a direction above both normals, 0 otherwise.
Eigen::Vector3f reflect_factor(const ShadingVertex& x, const Eigen::Vector3f& wi) {
    const float cos_shading = x.hit->shading_normal.dot(wi);
    if (cos_shading <= 0.0f || x.hit->geometric_normal.dot(wi) <= 0.0f) return Eigen::Vector3f::Zero();
    return eval_brdf(x.material, x.hit->shading_normal, x.wo, wi) * cos_shading;
}

// Adds a light term: traced as a shadow query when the light casts shadows, else added now.
struct QuerySink {
    std::vector<ShadowQuery>& queries;
    Eigen::Vector3f& unshadowed;
    const ShadingVertex& x;
    void add(bool cast_shadows, const Eigen::Vector3f& dir, float tfar, const Eigen::Vector3f& value, int group) {
        if (cast_shadows) {
            queries.push_back({x.origin, dir, tfar, value, std::min(group, kMaxQueryGroup)});
        } else {
            unshadowed += value;
        }
    }
};

// Environment: (1/N) Σ π f(wo, w) V(w) L_env over N = max(1, ao_samples) cosine-weighted
// directions (pdf cosθ/π), so f cosθ / pdf = π f. See integrator.h for why N >= 1.
void environment_queries(const FrameContext& frame, const ShadingVertex& x, const Eigen::Vector3f& throughput,
                         PixelSampler& sampler, QuerySink& sink) {
    const int count = std::max(1, frame.ao_samples);
    const PixelSampler::Pair pair = sampler.take();
    const Frame tangent(x.hit->shading_normal);
    const Eigen::Vector3f scale =
        throughput.cwiseProduct(frame.lights->environment) * (std::numbers::pi_v<float> / static_cast<float>(count));
    for (int s = 0; s < count; ++s) {
        const Eigen::Vector2f u = pair.point(s, count);
        const Eigen::Vector3f w = cosine_hemisphere(tangent, u.x(), u.y());
        if (x.hit->geometric_normal.dot(w) <= 0.0f) continue;  // into the surface itself
        sink.add(true, w, kInfinity, eval_brdf(x.material, x.hit->shading_normal, x.wo, w).cwiseProduct(scale), -1);
    }
}

// Point on an area light for sample u: direction, distance, cosθ_l; false if it cannot contribute.
struct AreaSample {
    Eigen::Vector3f wi;
    float distance = 0.0f;
    float distance2 = 0.0f;
    float cos_light = 0.0f;
};
bool sample_area(const PreparedArea& l, const Eigen::Vector3f& position, const Eigen::Vector2f& u, AreaSample& out) {
    const Eigen::Vector3f to_light = l.corner + u.x() * l.edge_u + u.y() * l.edge_v - position;
    out.distance2 = to_light.squaredNorm();
    if (!(out.distance2 > 0.0f)) return false;
    out.distance = std::sqrt(out.distance2);
    out.wi = to_light / out.distance;
    out.cos_light = -l.normal.dot(out.wi);
    return out.cos_light > 0.0f;  // one-sided emitter seen from behind
}

// Probability that the bounce at x samples the glossy lobe (0: cosine only; integrator.h).
float glossy_probability(const FrameContext& frame, const ShadingVertex& x) {
    if (!frame.glossy_vndf || !(x.hit->shading_normal.dot(x.wo) > 0.0f)) return 0.0f;
    return glossy_lobe_probability(x.material);
}

// Solid-angle pdf of the bounce direction wi at x: the one-sample mixture of the cosine lobe and
// the GGX visible-normal lobe (Veach 1997, §9.2.4's one-sample model with the balance heuristic).
float bounce_pdf(const FrameContext& frame, const ShadingVertex& x, const Eigen::Vector3f& wi) {
    const float cosine = x.hit->shading_normal.dot(wi) * std::numbers::inv_pi_v<float>;
    const float pg = glossy_probability(frame, x);
    if (pg == 0.0f) return cosine;
    return (1.0f - pg) * std::max(0.0f, cosine) +
           pg * ggx_reflection_pdf(x.hit->shading_normal, x.wo, wi, x.material.alpha);
}

// Power heuristic (Veach 1997, eq. 9.13 with β = 2) for n_f samples of pdf f against one of pdf g.
float power_heuristic(float nf_pdf_f, float pdf_g) {
    const float f2 = nf_pdf_f * nf_pdf_f;
    const float g2 = pdf_g * pdf_g;
    return f2 + g2 > 0.0f ? f2 / (f2 + g2) : 0.0f;
}

// Today's estimator: every light, area lights with area_light_samples rays each (integrator.h).
void legacy_light_queries(const FrameContext& frame, const ShadingVertex& x, const Eigen::Vector3f& throughput,
                          PixelSampler& sampler, QuerySink& sink) {
    const LightSet& lights = *frame.lights;
    int group = 0;
    for (const PreparedDirectional& l : lights.directional) {
        const Eigen::Vector3f f = reflect_factor(x, l.to_light);
        if (!f.isZero())
            sink.add(l.cast_shadows, l.to_light, kInfinity, throughput.cwiseProduct(f.cwiseProduct(l.irradiance)),
                     group);
        ++group;
    }
    for (const PreparedPoint& l : lights.point) {
        const Eigen::Vector3f to_light = l.position - x.hit->position;
        const float distance2 = to_light.squaredNorm();
        const int g = group++;
        if (!(distance2 > 0.0f)) continue;
        const float distance = std::sqrt(distance2);
        const Eigen::Vector3f wi = to_light / distance;
        const Eigen::Vector3f f = reflect_factor(x, wi);
        if (f.isZero()) continue;
        sink.add(l.cast_shadows, wi, kShadowEnd * distance,
                 throughput.cwiseProduct(f.cwiseProduct(l.intensity) / distance2), g);
    }
    const int n = frame.area_light_samples;
    const float weight = 1.0f / static_cast<float>(n);
    for (const PreparedArea& l : lights.area) {
        const PixelSampler::Pair pair = sampler.take();
        const int g = group++;
        for (int s = 0; s < n; ++s) {
            AreaSample a;
            if (!sample_area(l, x.hit->position, pair.point(s, n), a)) continue;
            const Eigen::Vector3f f = reflect_factor(x, a.wi);
            if (f.isZero()) continue;
            sink.add(
                l.cast_shadows, a.wi, kShadowEnd * a.distance,
                throughput.cwiseProduct(f.cwiseProduct(l.radiance)) * (weight * a.cos_light * l.area / a.distance2), g);
        }
    }
}

// One light sample: light i chosen with probability sel.pdf[i], weighted by 1 / (n p_i).
void one_light_query(const FrameContext& frame, const ShadingVertex& x, const Eigen::Vector3f& throughput,
                     const LightSelection& sel, Eigen::Vector2f u, bool bounce_follows, QuerySink& sink) {
    const LightSet& lights = *frame.lights;
    const int i = sel.sample(u.x());
    const float n = static_cast<float>(frame.area_light_samples);
    const float scale = 1.0f / (n * sel.pdf[i]);
    const auto nd = static_cast<int>(lights.directional.size());
    const auto np = static_cast<int>(lights.point.size());
    if (i < nd) {
        const PreparedDirectional& l = lights.directional[static_cast<std::size_t>(i)];
        const Eigen::Vector3f f = reflect_factor(x, l.to_light);
        if (!f.isZero())
            sink.add(l.cast_shadows, l.to_light, kInfinity,
                     throughput.cwiseProduct(f.cwiseProduct(l.irradiance)) * scale, i);
        return;
    }
    if (i < nd + np) {
        const PreparedPoint& l = lights.point[static_cast<std::size_t>(i - nd)];
        const Eigen::Vector3f to_light = l.position - x.hit->position;
        const float distance2 = to_light.squaredNorm();
        if (!(distance2 > 0.0f)) return;
        const float distance = std::sqrt(distance2);
        const Eigen::Vector3f wi = to_light / distance;
        const Eigen::Vector3f f = reflect_factor(x, wi);
        if (!f.isZero())
            sink.add(l.cast_shadows, wi, kShadowEnd * distance,
                     throughput.cwiseProduct(f.cwiseProduct(l.intensity)) * (scale / distance2), i);
        return;
    }
    const PreparedArea& l = lights.area[static_cast<std::size_t>(i - nd - np)];
    AreaSample a;
    if (!sample_area(l, x.hit->position, u, a)) return;
    const Eigen::Vector3f f = reflect_factor(x, a.wi);
    if (f.isZero()) return;
    float mis = 1.0f;
    if (bounce_follows) {
        const float pdf_light = sel.pdf[i] * a.distance2 / (a.cos_light * l.area);  // solid angle
        mis = power_heuristic(n * pdf_light, bounce_pdf(frame, x, a.wi));
    }
    sink.add(l.cast_shadows, a.wi, kShadowEnd * a.distance,
             throughput.cwiseProduct(f.cwiseProduct(l.radiance)) * (scale * mis * a.cos_light * l.area / a.distance2),
             i);
}

// Ray-parallelogram intersection (the light is not in the BVH): distance along dir, or < 0.
float hit_area(const PreparedArea& l, const Eigen::Vector3f& org, const Eigen::Vector3f& dir) {
    const float denom = l.normal.dot(dir);
    if (!(denom < 0.0f)) return -1.0f;  // parallel or from behind the one-sided emitter
    const float t = l.normal.dot(l.corner - org) / denom;
    if (!(t > 0.0f)) return -1.0f;
    // p = s edge_u + r edge_v (edges need not be orthogonal): the 2x2 normal equations.
    const Eigen::Vector3f p = org + t * dir - l.corner;
    const float a = l.edge_u.squaredNorm();
    const float b = l.edge_u.dot(l.edge_v);
    const float c = l.edge_v.squaredNorm();
    const float pu = p.dot(l.edge_u);
    const float pv = p.dot(l.edge_v);
    const float det = a * c - b * b;
    const float s = (c * pu - b * pv) / det;
    const float r = (a * pv - b * pu) / det;
    return s >= 0.0f && s <= 1.0f && r >= 0.0f && r <= 1.0f ? t : -1.0f;
}

}  // namespace

ShadingVertex make_vertex(const FrameContext& frame, const SurfaceHit& hit, const Eigen::Vector3f& wo) {
    const ShadingMaterial& base = (*frame.materials)[hit.material];
    return {&hit, hit.tinted ? tinted_material(base, hit.tint) : base, wo,
            offset_ray_origin(hit.position, hit.geometric_normal)};
}

ShadingMaterial white_lambert() {
    Material white;
    white.albedo = Eigen::Vector3f::Ones();
    white.specular = Eigen::Vector3f::Zero();
    return make_shading_material(white);
}

void direct_light_queries(const FrameContext& frame, const ShadingVertex& x, const Eigen::Vector3f& throughput,
                          bool bounce_follows, PixelSampler& sampler, std::vector<ShadowQuery>& queries,
                          Eigen::Vector3f& unshadowed, DirectParts parts) {
    QuerySink sink{queries, unshadowed, x};
    if (parts == DirectParts::kEnvironmentOnly) {
        if (frame.lights->has_environment) environment_queries(frame, x, throughput, sampler, sink);
        return;
    }
    const int lights = selectable_light_count(*frame.lights);
    if (frame.legacy_light_sampling || lights > kMaxSelectableLights) {
        legacy_light_queries(frame, x, throughput, sampler, sink);
    } else if (lights > 0) {
        const LightSelection sel = select_lights(*frame.lights, x.hit->position, x.hit->shading_normal);
        const PixelSampler::Pair pair = sampler.take();
        for (int s = 0; s < frame.area_light_samples; ++s) {
            one_light_query(frame, x, throughput, sel, pair.point(s, frame.area_light_samples), bounce_follows, sink);
        }
    }
    if (parts == DirectParts::kAll && frame.lights->has_environment && !environment_from_bounce(frame, bounce_follows))
        environment_queries(frame, x, throughput, sampler, sink);
}

bool sample_bounce(const FrameContext& frame, const ShadingVertex& x, const Eigen::Vector3f& throughput, int depth,
                   PixelSampler& sampler, Bounce& out) {
    const Eigen::Vector2f u = sampler.next2d();
    const Eigen::Vector3f& n = x.hit->shading_normal;
    const Frame tangent(n);
    const float pg = glossy_probability(frame, x);
    if (u.x() < pg) {  // the glossy lobe: reflect wo about a visible GGX normal (Heitz 2018)
        const Eigen::Vector3f wo_local(tangent.t.dot(x.wo), tangent.b.dot(x.wo), n.dot(x.wo));
        const Eigen::Vector3f h = tangent.to_world(ggx_visible_normal(wo_local, x.material.alpha, u.x() / pg, u.y()));
        out.direction = (2.0f * x.wo.dot(h) * h - x.wo).normalized();
    } else {  // the cosine lobe; u.x() remapped to [0, 1) (PBRT 4th ed. §A.1), unchanged when pg = 0
        out.direction = cosine_hemisphere(tangent, pg > 0.0f ? (u.x() - pg) / (1.0f - pg) : u.x(), u.y());
    }
    if (x.hit->geometric_normal.dot(out.direction) <= 0.0f) return false;
    const Eigen::Vector3f f = eval_brdf(x.material, n, x.wo, out.direction);
    if (pg > 0.0f) {  // f cosθ / pdf with the mixture's pdf (one-sample MIS, balance heuristic)
        const float pdf = bounce_pdf(frame, x, out.direction);
        const float cos_i = n.dot(out.direction);
        if (!(pdf > 0.0f) || !(cos_i > 0.0f)) return false;
        out.throughput = throughput.cwiseProduct(f) * (cos_i / pdf);
    } else {  // f cosθ / pdf with pdf = cosθ/π (PBRT 4th ed. §13.1)
        out.throughput = throughput.cwiseProduct(f) * std::numbers::pi_v<float>;
    }
    const float largest = out.throughput.maxCoeff();
    if (!(largest > 0.0f)) return false;
    if (frame.russian_roulette && depth >= kRouletteMinDepth && largest < 1.0f) {
        // Survive with q = sqrt of the largest channel; divide by q (Arvo & Kirk 1990; integrator.h).
        const float q = std::sqrt(largest);
        if (sampler.next2d().x() >= q) return false;
        out.throughput /= q;
    }
    return true;
}

Eigen::Vector3f bounce_emission(const FrameContext& frame, const ShadingVertex& x, const Eigen::Vector3f& dir,
                                float t_hit, const Eigen::Vector3f& throughput) {
    const LightSet& lights = *frame.lights;
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();
    if (frame.legacy_light_sampling || lights.area.empty() || selectable_light_count(lights) > kMaxSelectableLights) {
        return sum;
    }
    const auto first_area = static_cast<int>(lights.directional.size() + lights.point.size());
    LightSelection sel;
    bool have_selection = false;
    for (std::size_t k = 0; k < lights.area.size(); ++k) {
        const PreparedArea& l = lights.area[k];
        const float t = hit_area(l, x.origin, dir);
        if (!(t > 0.0f) || (l.cast_shadows && !(t < t_hit))) continue;
        if (!have_selection) {
            sel = select_lights(lights, x.hit->position, x.hit->shading_normal);
            have_selection = true;
        }
        const float cos_light = -l.normal.dot(dir);
        const float pdf_light = sel.pdf[first_area + static_cast<int>(k)] * t * t / (cos_light * l.area);
        const float n = static_cast<float>(frame.area_light_samples);
        sum += throughput.cwiseProduct(l.radiance) * power_heuristic(bounce_pdf(frame, x, dir), n * pdf_light);
    }
    return sum;
}

Eigen::Vector3f radiance_at(const FrameContext& frame, const SurfaceHit& first, const Eigen::Vector3f& first_wo,
                            PixelSampler& sampler, std::uint64_t& rays, RecordedRays* log) {
    Eigen::Vector3f radiance = Eigen::Vector3f::Zero();
    Eigen::Vector3f throughput = Eigen::Vector3f::Ones();
    SurfaceHit hit = first;
    Eigen::Vector3f wo = first_wo;
    thread_local std::vector<ShadowQuery> queries;  // reused: no allocation per pixel sample
    for (int depth = 0;; ++depth) {
        const ShadingVertex x = make_vertex(frame, hit, wo);
        const bool bounce_follows = depth < frame.max_bounces;
        queries.clear();
        direct_light_queries(frame, x, throughput, bounce_follows, sampler, queries, radiance);
        for (const ShadowQuery& q : queries) {
            if (!occluded(frame.scene->root(), q.origin, q.direction, q.tfar, rays, log)) radiance += q.contribution;
        }
        if (!bounce_follows) break;
        Bounce bounce;
        if (!sample_bounce(frame, x, throughput, depth, sampler, bounce)) break;

        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
        RTCRayHit ray_hit{};
        ray_hit.ray = make_ray(x.origin, bounce.direction, kInfinity);
        ray_hit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        ray_hit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        record_single(log, x.origin, bounce.direction, kInfinity, false);
        rtcIntersect1(frame.scene->root(), &context, &ray_hit);
        ++rays;
        const bool escaped = ray_hit.hit.geomID == RTC_INVALID_GEOMETRY_ID;
        if (escaped && environment_from_bounce(frame, true) && frame.lights->has_environment)
            radiance += bounce.throughput.cwiseProduct(frame.lights->environment);
        radiance +=
            bounce_emission(frame, x, bounce.direction, escaped ? kInfinity : ray_hit.ray.tfar, bounce.throughput);
        if (escaped) break;  // see header
        hit = frame.scene->surface(x.origin, bounce.direction, ray_hit.ray.tfar, ray_hit.hit.instID[0],
                                   ray_hit.hit.geomID, ray_hit.hit.primID, ray_hit.hit.u, ray_hit.hit.v,
                                   Eigen::Vector3f(ray_hit.hit.Ng_x, ray_hit.hit.Ng_y, ray_hit.hit.Ng_z),
                                   x.hit->cone_width + frame.cone_spread * ray_hit.ray.tfar);
        throughput = bounce.throughput;
        wo = -bounce.direction;
    }
    return radiance;
}

}  // namespace mogao
