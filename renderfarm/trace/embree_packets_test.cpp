// SPDX-License-Identifier: Apache-2.0
// occluded16_at / intersect16_at against Embree's single-ray queries at every packet width (the
// device's native one, 16, 8 and 4), with the coherent flag the renderer's packets carry and with
// masked lanes left zero as the renderer leaves them, on the two-level (instanced) layout the
// renderer builds.
#include <array>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "renderfarm/trace/embree_device.h"
#include "renderfarm/trace/embree_packets.h"
#include "renderfarm/trace/embree_scene.h"

namespace mogao {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// A floor quad (z = 0, 4 m square) and a blocker triangle at z = 1 over its x < 0 half, as one
// mesh instanced once in a top-level scene: the two-level layout the renderer builds.
struct TwoLevelScene {
    EmbreeDevice device;
    EmbreeScene mesh{device};
    EmbreeScene root{device};

    TwoLevelScene() {
        EmbreeGeometry triangles(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        // The floor as a kGrid x kGrid grid of quads (a BVH several levels deep), then the blocker.
        constexpr int kGrid = 64;
        constexpr int kFloorVertices = (kGrid + 1) * (kGrid + 1);
        constexpr int kTriangles = 2 * kGrid * kGrid + 1;
        auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
            triangles.get(), RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), kFloorVertices + 3));
        for (int j = 0, k = 0; j <= kGrid; ++j) {
            for (int i = 0; i <= kGrid; ++i, k += 3) {
                vb[k] = -2.0f + 4.0f * static_cast<float>(i) / kGrid;
                vb[k + 1] = -2.0f + 4.0f * static_cast<float>(j) / kGrid;
                vb[k + 2] = 0.0f;
            }
        }
        const std::array<float, 9> blocker = {-2, -2, 1, 0, 0, 1, -2, 2, 1};
        std::copy(blocker.begin(), blocker.end(), vb + 3 * kFloorVertices);
        auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(triangles.get(), RTC_BUFFER_TYPE_INDEX, 0,
                                                                  RTC_FORMAT_UINT3, 3 * sizeof(unsigned), kTriangles));
        for (int j = 0, k = 0; j < kGrid; ++j) {
            for (int i = 0; i < kGrid; ++i, k += 6) {
                const auto a = static_cast<unsigned>(j * (kGrid + 1) + i);
                const unsigned b = a + 1, c = a + kGrid + 2, d = a + kGrid + 1;
                const std::array<unsigned, 6> quad = {a, b, c, a, c, d};
                std::copy(quad.begin(), quad.end(), ib + k);
            }
        }
        const auto first = static_cast<unsigned>(kFloorVertices);
        ib[3 * (kTriangles - 1)] = first;
        ib[3 * (kTriangles - 1) + 1] = first + 1;
        ib[3 * (kTriangles - 1) + 2] = first + 2;
        rtcCommitGeometry(triangles.get());
        rtcAttachGeometry(mesh.get(), triangles.get());
        rtcCommitScene(mesh.get());
        EmbreeGeometry instance(device, RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(instance.get(), mesh.get());
        const std::array<float, 12> identity = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
        rtcSetGeometryTransform(instance.get(), 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, identity.data());
        rtcCommitGeometry(instance.get());
        rtcAttachGeometry(root.get(), instance.get());
        rtcCommitScene(root.get());
        device.check("two-level scene");
    }
};

// Lane l: from a point just above the floor, x in [-1.9, 1.9], toward a light at (0, 0, 3).
void shadow_ray(RTCRay16& r, int l) {
    const float x = -1.9f + 3.8f * static_cast<float>(l) / 15.0f;
    const float y = 0.1f * static_cast<float>(l % 4) - 0.15f;
    const float dx = -x, dy = -y, dz = 3.0f - 0.01f;
    const float length = std::sqrt(dx * dx + dy * dy + dz * dz);
    r.org_x[l] = x;
    r.org_y[l] = y;
    r.org_z[l] = 0.01f;
    r.dir_x[l] = dx / length;
    r.dir_y[l] = dy / length;
    r.dir_z[l] = dz / length;
    r.tnear[l] = 0.0f;
    r.tfar[l] = length;
    r.time[l] = 0.0f;
    r.mask[l] = ~0u;
    r.id[l] = static_cast<unsigned>(l);
    r.flags[l] = 0;
}

bool occluded_single(RTCScene scene, const RTCRay16& r, int l) {
    RTCRay ray{};
    ray.org_x = r.org_x[l];
    ray.org_y = r.org_y[l];
    ray.org_z = r.org_z[l];
    ray.dir_x = r.dir_x[l];
    ray.dir_y = r.dir_y[l];
    ray.dir_z = r.dir_z[l];
    ray.tfar = r.tfar[l];
    ray.mask = ~0u;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    rtcOccluded1(scene, &context, &ray);
    return ray.tfar < 0.0f;
}

TEST(EmbreePackets, CoherentOcclusionPacketsMatchSingleRaysAtEveryWidth) {
    TwoLevelScene s;
    const int native = native_packet_width(s.root.get());
    for (const int width : {native, 16, 8, 4}) {
        for (const bool all_lanes : {true, false}) {
            alignas(64) std::array<int, 16> valid{};
            RTCRay16 ray{};
            for (int l = 0; l < 16; ++l) {
                valid[static_cast<std::size_t>(l)] = all_lanes || l % 3 != 0 ? -1 : 0;
                // A masked lane stays zero, direction included, as the renderer leaves it.
                if (valid[static_cast<std::size_t>(l)] != 0) shadow_ray(ray, l);
            }
            const RTCRay16 before = ray;
            RTCIntersectContext context;
            rtcInitIntersectContext(&context);
            context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
            occluded16_at(width, valid.data(), s.root.get(), &context, ray);
            int blocked = 0;
            for (int l = 0; l < 16; ++l) {
                const auto i = static_cast<std::size_t>(l);
                SCOPED_TRACE(testing::Message() << "width " << width << " lane " << l);
                if (valid[i] == 0) {
                    EXPECT_EQ(ray.tfar[l], before.tfar[l]);  // a masked lane is left alone
                    continue;
                }
                const bool single = occluded_single(s.root.get(), before, l);
                EXPECT_EQ(ray.tfar[l] < 0.0f, single);
                blocked += single ? 1 : 0;
            }
            EXPECT_GT(blocked, 0);                    // the blocker shades part of the floor ...
            EXPECT_LT(blocked, all_lanes ? 16 : 10);  // ... not all of it
        }
    }
}

TEST(EmbreePackets, CoherentIntersectionPacketsMatchSingleRaysAtEveryWidth) {
    TwoLevelScene s;
    for (const int width : {native_packet_width(s.root.get()), 16, 8, 4}) {
        alignas(64) std::array<int, 16> valid{};
        RTCRayHit16 packet{};
        for (int l = 0; l < 16; ++l) {
            valid[static_cast<std::size_t>(l)] = -1;
            shadow_ray(packet.ray, l);
            packet.ray.tfar[l] = kInf;
            packet.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
            packet.hit.instID[0][l] = RTC_INVALID_GEOMETRY_ID;
        }
        RTCRay16 rays = packet.ray;
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        intersect16_at(width, valid.data(), s.root.get(), &context, packet);
        for (int l = 0; l < 16; ++l) {
            SCOPED_TRACE(testing::Message() << "width " << width << " lane " << l);
            rays.tfar[l] = kInf;
            const bool single = occluded_single(s.root.get(), rays, l);
            EXPECT_EQ(packet.hit.geomID[l] != RTC_INVALID_GEOMETRY_ID, single);
        }
    }
}

}  // namespace
}  // namespace mogao
