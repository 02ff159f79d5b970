// SPDX-License-Identifier: Apache-2.0
// 16-lane ray packets traced at the width the CPU runs natively. Embree 3 emulates a packet width
// its build has no kernels for (RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED = 0 on a CPU without
// AVX-512: rtcIntersect16 then traces the lanes one at a time, losing the packet's coherence).
// These split a 4x4-block packet into two 4x2 halves (rtcIntersect8/rtcOccluded8, AVX2) or four
// 4x1 rows (width 4, SSE) that are traced as native packets, skipping empty parts, and copy the
// results back, so callers keep one 16-lane layout (lane = 4 y + x in the block) whatever the CPU.
// Embree API reference: rtcIntersect4/8/16, rtcOccluded4/8/16, rtcGetDeviceProperty.
#pragma once

#include <embree3/rtcore.h>

namespace mogao {

// 16, 8 or 4: the widest packet the device traces natively (4 if it reports none).
[[nodiscard]] int native_packet_width(RTCScene scene);

// As rtcIntersect16 / rtcOccluded16 (valid: -1 trace, 0 masked), traced as packets of `width`
// lanes (16, 8 or 4; anything else is treated as 16).
void intersect16_at(int width, const int* valid, RTCScene scene, RTCIntersectContext* context, RTCRayHit16& packet);
void occluded16_at(int width, const int* valid, RTCScene scene, RTCIntersectContext* context, RTCRay16& ray);

}  // namespace mogao
