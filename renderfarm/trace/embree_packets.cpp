// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/trace/embree_packets.h"

#include <cstddef>

namespace mogao {
namespace {

template <typename Dst, typename Src>
void copy_ray(Dst& d, std::size_t i, const Src& s, std::size_t j) {
    d.org_x[i] = s.org_x[j];
    d.org_y[i] = s.org_y[j];
    d.org_z[i] = s.org_z[j];
    d.tnear[i] = s.tnear[j];
    d.dir_x[i] = s.dir_x[j];
    d.dir_y[i] = s.dir_y[j];
    d.dir_z[i] = s.dir_z[j];
    d.time[i] = s.time[j];
    d.tfar[i] = s.tfar[j];
    d.mask[i] = s.mask[j];
    d.id[i] = s.id[j];
    d.flags[i] = s.flags[j];
}

template <typename Dst, typename Src>
void copy_hit(Dst& d, std::size_t i, const Src& s, std::size_t j) {
    d.Ng_x[i] = s.Ng_x[j];
    d.Ng_y[i] = s.Ng_y[j];
    d.Ng_z[i] = s.Ng_z[j];
    d.u[i] = s.u[j];
    d.v[i] = s.v[j];
    d.primID[i] = s.primID[j];
    d.geomID[i] = s.geomID[j];
    d.instID[0][i] = s.instID[0][j];
}

// Part `part` of `N` lanes: copies in, traces with `trace`, copies results out.
template <std::size_t N, typename Packet, typename Trace>
void trace_part(std::size_t part, const int* valid, Packet& packet, Trace&& trace) {
    alignas(64) int part_valid[N];
    bool any = false;
    for (std::size_t i = 0; i < N; ++i) {
        part_valid[i] = valid[part * N + i];
        any |= part_valid[i] != 0;
    }
    if (any) trace(part_valid, packet, part * N);
}

template <std::size_t N, typename RayHitN, typename Fn>
void intersect_split(const int* valid, RTCRayHit16& packet, Fn&& intersect) {
    for (std::size_t part = 0; part < 16 / N; ++part) {
        trace_part<N>(part, valid, packet, [&](const int* v, RTCRayHit16& p, std::size_t first) {
            RayHitN sub{};
            for (std::size_t i = 0; i < N; ++i) {
                copy_ray(sub.ray, i, p.ray, first + i);
                copy_hit(sub.hit, i, p.hit, first + i);
            }
            intersect(v, &sub);
            for (std::size_t i = 0; i < N; ++i) {
                copy_ray(p.ray, first + i, sub.ray, i);
                copy_hit(p.hit, first + i, sub.hit, i);
            }
        });
    }
}

template <std::size_t N, typename RayN, typename Fn>
void occluded_split(const int* valid, RTCRay16& ray, Fn&& occluded) {
    for (std::size_t part = 0; part < 16 / N; ++part) {
        trace_part<N>(part, valid, ray, [&](const int* v, RTCRay16& r, std::size_t first) {
            RayN sub{};
            for (std::size_t i = 0; i < N; ++i) copy_ray(sub, i, r, first + i);
            occluded(v, &sub);
            for (std::size_t i = 0; i < N; ++i) r.tfar[first + i] = sub.tfar[i];
        });
    }
}

}  // namespace

int native_packet_width(RTCScene scene) {
    const RTCDevice device = rtcGetSceneDevice(scene);  // holds a reference (Embree API)
    int width = 4;
    if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED) != 0) {
        width = 16;
    } else if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED) != 0) {
        width = 8;
    }
    rtcReleaseDevice(device);
    return width;
}

void intersect16_at(int width, const int* valid, RTCScene scene, RTCIntersectContext* context, RTCRayHit16& packet) {
    if (width == 8) {
        intersect_split<8, RTCRayHit8>(valid, packet,
                                       [&](const int* v, RTCRayHit8* p) { rtcIntersect8(v, scene, context, p); });
    } else if (width == 4) {
        intersect_split<4, RTCRayHit4>(valid, packet,
                                       [&](const int* v, RTCRayHit4* p) { rtcIntersect4(v, scene, context, p); });
    } else {
        rtcIntersect16(valid, scene, context, &packet);
    }
}

void occluded16_at(int width, const int* valid, RTCScene scene, RTCIntersectContext* context, RTCRay16& ray) {
    if (width == 8) {
        occluded_split<8, RTCRay8>(valid, ray, [&](const int* v, RTCRay8* r) { rtcOccluded8(v, scene, context, r); });
    } else if (width == 4) {
        occluded_split<4, RTCRay4>(valid, ray, [&](const int* v, RTCRay4* r) { rtcOccluded4(v, scene, context, r); });
    } else {
        rtcOccluded16(valid, scene, context, &ray);
    }
}

}  // namespace mogao
