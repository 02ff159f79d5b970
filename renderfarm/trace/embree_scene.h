// SPDX-License-Identifier: Apache-2.0
// RAII owners of an Embree scene (RTCScene) and geometry (RTCGeometry).
//
// Embree reference-counts both: attaching a geometry to a scene, or instancing a scene, takes its
// own reference, so these owners may be destroyed in any order (rtcRelease* drops only ours).
// Non-copyable, movable (UniqueHandle, common/unique_handle.h); a moved-from owner holds nullptr.
#pragma once

#include <embree3/rtcore.h>

#include "common/unique_handle.h"
#include "renderfarm/trace/embree_device.h"

namespace mogao {

class EmbreeScene {
public:
    // Throws std::runtime_error (via device.check) if Embree cannot create the scene.
    explicit EmbreeScene(const EmbreeDevice& device);

    [[nodiscard]] RTCScene get() const noexcept { return scene_.get(); }

private:
    struct Traits {
        using Value = RTCScene;
        static constexpr RTCScene null() noexcept { return nullptr; }
        static void close(RTCScene scene) noexcept { rtcReleaseScene(scene); }
    };
    UniqueHandle<Traits> scene_;
};

class EmbreeGeometry {
public:
    // Throws std::runtime_error (via device.check) if Embree cannot create the geometry.
    EmbreeGeometry(const EmbreeDevice& device, RTCGeometryType type);

    [[nodiscard]] RTCGeometry get() const noexcept { return geometry_.get(); }

private:
    struct Traits {
        using Value = RTCGeometry;
        static constexpr RTCGeometry null() noexcept { return nullptr; }
        static void close(RTCGeometry geometry) noexcept { rtcReleaseGeometry(geometry); }
    };
    UniqueHandle<Traits> geometry_;
};

}  // namespace mogao
