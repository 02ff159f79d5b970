// SPDX-License-Identifier: Apache-2.0
// Benchmark support: the secondary rays (shadow, environment, bounce) a render traced, kept so
// that raw Embree can trace exactly the same ray mix without any shading (Renderer::trace_recorded,
// bench/render_vs_embree.cpp). Rays are in the renderer's rebased float frame.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace mogao {

struct RecordedPacket {
    static constexpr int kLanes = 16;
    alignas(64) std::array<int, kLanes> valid{};  // -1 = traced, 0 = masked (Embree convention)
    std::array<float, kLanes> org_x{}, org_y{}, org_z{}, dir_x{}, dir_y{}, dir_z{}, tfar{};
    bool occlusion = true;    // rtcOccluded* (shadow/environment) or rtcIntersect* (bounce)
    bool packet = true;       // traced as one 16-wide packet; false: every valid lane as a single ray
    bool coherent = false;    // the intersect context flag it was traced with
    bool starts_call = true;  // first packet of one trace_queries / bounce call (a block's vertex)
    std::uint8_t depth = 0;   // path vertex the rays leave (0 = the camera ray's hit; packet path only)
};

struct RecordedRays {
    std::vector<RecordedPacket> packets;
    [[nodiscard]] std::uint64_t ray_count() const {
        std::uint64_t n = 0;
        for (const RecordedPacket& p : packets)
            for (int v : p.valid) n += v != 0 ? 1u : 0u;
        return n;
    }
};

}  // namespace mogao
