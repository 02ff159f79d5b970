// SPDX-License-Identifier: Apache-2.0
#include <sys/types.h>

#include <algorithm>
#include <atomic>
#include <iterator>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

#include <gtest/gtest.h>

#include "renderfarm/trace/embree_device.h"
#include "renderfarm/trace/embree_scene.h"

namespace mogao {
namespace {

static_assert(!std::is_copy_constructible_v<EmbreeDevice> && std::is_nothrow_move_constructible_v<EmbreeDevice> &&
              std::is_nothrow_move_assignable_v<EmbreeDevice>);
static_assert(!std::is_copy_constructible_v<EmbreeScene> && std::is_nothrow_move_assignable_v<EmbreeScene>);
static_assert(!std::is_copy_constructible_v<EmbreeGeometry> && std::is_nothrow_move_assignable_v<EmbreeGeometry>);

// Embree's memory monitor: bytes before each allocation, minus the bytes after each free.
bool count_bytes(void* user, ssize_t bytes, bool /*post*/) {
    static_cast<std::atomic<long long>*>(user)->fetch_add(bytes);
    return true;
}

// A committed scene of one triangle at z = -5 facing +z; the geometry's owner is gone on return,
// so the scene holds the only reference to it.
EmbreeScene triangle_scene(const EmbreeDevice& device) {
    EmbreeScene scene(device);
    EmbreeGeometry triangle(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(
        rtcSetNewGeometryBuffer(triangle.get(), RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3));
    const float vertices[9] = {-1, -1, -5, 1, -1, -5, 0, 1, -5};
    std::copy(std::begin(vertices), std::end(vertices), v);
    auto* index = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(triangle.get(), RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), 1));
    index[0] = 0;
    index[1] = 1;
    index[2] = 2;
    rtcCommitGeometry(triangle.get());
    rtcAttachGeometry(scene.get(), triangle.get());
    rtcCommitScene(scene.get());
    device.check("triangle scene");
    return scene;
}

bool ray_down_z_hits(RTCScene scene) {
    RTCRayHit rh{};
    rh.ray.dir_z = -1;
    rh.ray.tfar = std::numeric_limits<float>::infinity();
    rh.ray.mask = ~0u;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    rtcIntersect1(scene, &context, &rh);
    return rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
}

TEST(EmbreeRaii, MovesTransferOwnership) {
    EmbreeDevice device("threads=1");
    ASSERT_NE(device.get(), nullptr);
    EmbreeScene scene(device);
    const RTCScene handle = scene.get();
    EmbreeScene moved(std::move(scene));
    EXPECT_EQ(moved.get(), handle);
    EXPECT_EQ(scene.get(), nullptr);  // NOLINT(bugprone-use-after-move): documented moved-from state

    EmbreeGeometry geometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    EmbreeGeometry other(device, RTC_GEOMETRY_TYPE_INSTANCE);
    other = std::move(geometry);
    EXPECT_EQ(geometry.get(), nullptr);  // NOLINT(bugprone-use-after-move)
    EXPECT_NE(other.get(), nullptr);

    EmbreeDevice device2 = std::move(device);
    EXPECT_EQ(device.get(), nullptr);  // NOLINT(bugprone-use-after-move)
    EXPECT_NE(device2.get(), nullptr);
}

TEST(EmbreeRaii, MovedSceneIsReleasedOnceByItsLastOwner) {
    EmbreeDevice device("threads=1");
    std::atomic<long long> bytes{0};
    rtcSetDeviceMemoryMonitorFunction(device.get(), count_bytes, &bytes);

    std::optional<EmbreeScene> source(triangle_scene(device));
    const long long one_scene = bytes.load();
    ASSERT_GT(one_scene, 0) << "Embree reported no memory for a built BVH; this test cannot observe releases";
    const RTCScene handle = source->get();
    EmbreeScene target(std::move(*source));
    EXPECT_EQ(source->get(), nullptr);  // NOLINT(bugprone-use-after-move)
    EXPECT_EQ(target.get(), handle);
    source.reset();
    EXPECT_EQ(bytes.load(), one_scene) << "destroying the moved-from owner released the scene";
    EXPECT_TRUE(ray_down_z_hits(target.get()));

    // Assignment releases the target's old scene, and keeps the new one alive and usable.
    EmbreeScene other = triangle_scene(device);
    const long long two_scenes = bytes.load();
    target = std::move(other);
    EXPECT_EQ(other.get(), nullptr);  // NOLINT(bugprone-use-after-move)
    EXPECT_LT(bytes.load(), two_scenes) << "the replaced scene was not released";
    const long long after_assignment = bytes.load();
    { EmbreeScene dropped = std::move(other); }
    EXPECT_EQ(bytes.load(), after_assignment);
    EXPECT_TRUE(ray_down_z_hits(target.get()));
    target = EmbreeScene(device);
    EXPECT_LT(bytes.load(), after_assignment);
}

TEST(EmbreeRaii, MovedDeviceIsReleasedOnceByItsLastOwner) {
    RTCDevice raw = nullptr;
    {
        EmbreeDevice source("threads=1");
        raw = source.get();
        rtcRetainDevice(raw);  // the test's own reference, which outlives every owner
        EmbreeDevice target(std::move(source));
        EXPECT_EQ(source.get(), nullptr);  // NOLINT(bugprone-use-after-move)
        EmbreeDevice assigned("threads=1");
        assigned = std::move(target);
        EXPECT_EQ(target.get(), nullptr);  // NOLINT(bugprone-use-after-move)
        EXPECT_EQ(assigned.get(), raw);
        EXPECT_NO_THROW(assigned.check("after moves"));
    }
    // Three owners held one reference between them; ours keeps the device alive. A second release
    // would have freed it under us (a use after free that the sanitizer build reports).
    EXPECT_EQ(rtcGetDeviceProperty(raw, RTC_DEVICE_PROPERTY_VERSION), RTC_VERSION);
    RTCScene scene = rtcNewScene(raw);
    EXPECT_NE(scene, nullptr);
    EXPECT_EQ(rtcGetDeviceError(raw), RTC_ERROR_NONE);
    rtcReleaseScene(scene);
    rtcReleaseDevice(raw);
}

TEST(EmbreeRaii, EmbreeErrorsBecomeExceptions) {
    EmbreeDevice device("threads=1");
    EmbreeGeometry triangles(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Triangles cannot take an instance transform: RTC_ERROR_INVALID_OPERATION.
    const float identity[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    rtcSetGeometryTransform(triangles.get(), 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, identity);
    try {
        device.check("transform on triangles");
        FAIL() << "no exception";
    } catch (const std::runtime_error& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("transform on triangles"), std::string::npos) << message;
        EXPECT_NE(message.find("RTC_ERROR_INVALID_OPERATION"), std::string::npos) << message;
        EXPECT_NE(message.find("not supported"), std::string::npos) << message;  // Embree's own text
    }
    EXPECT_NO_THROW(device.check("nothing failed since"));
}

TEST(EmbreeRaii, BadDeviceConfigThrows) { EXPECT_THROW(EmbreeDevice("threads=abc"), std::runtime_error); }

}  // namespace
}  // namespace mogao

namespace mogao {
namespace {

// embree_device.h: AVX-512 kernels are never used unless a configuration asks for an ISA itself
// (Debian 12's Embree 3.13.5 hung in its AVX-512 rtcOccluded16 on an AMD EPYC).
TEST(EmbreeDeviceIsa, CapsTheIsaAtAvx2UnlessTheConfigurationNamesOne) {
    EXPECT_EQ(EmbreeDevice::effective_config(""), "max_isa=avx2");
    EXPECT_EQ(EmbreeDevice::effective_config("threads=2"), "threads=2,max_isa=avx2");
    EXPECT_EQ(EmbreeDevice::effective_config("threads=1,isa=sse4.2"), "threads=1,isa=sse4.2");
    EXPECT_EQ(EmbreeDevice::effective_config("max_isa=avx"), "max_isa=avx");
    const EmbreeDevice device("threads=1");
    EXPECT_EQ(rtcGetDeviceProperty(device.get(), RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED), 0);
}

}  // namespace
}  // namespace mogao
