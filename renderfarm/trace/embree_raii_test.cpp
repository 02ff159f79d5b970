#include <stdexcept>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "renderfarm/trace/embree_device.h"
#include "renderfarm/trace/embree_scene.h"

namespace mogao {
namespace {

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

TEST(EmbreeRaii, BadDeviceConfigThrows) {
    EXPECT_THROW(EmbreeDevice("threads=abc"), std::runtime_error);
}

}  // namespace
}  // namespace mogao
