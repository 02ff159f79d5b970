// RAII owners of an Embree scene (RTCScene) and geometry (RTCGeometry).
//
// Embree reference-counts both: attaching a geometry to a scene, or instancing a scene, takes its
// own reference, so these owners may be destroyed in any order (rtcRelease* drops only ours).
// Non-copyable, movable; a moved-from owner holds nullptr.
#pragma once

#include <embree3/rtcore.h>

#include "renderfarm/trace/embree_device.h"

namespace mogao {

class EmbreeScene {
public:
    // Throws std::runtime_error (via device.check) if Embree cannot create the scene.
    explicit EmbreeScene(const EmbreeDevice& device);
    ~EmbreeScene();
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;
    EmbreeScene(EmbreeScene&& other) noexcept;
    EmbreeScene& operator=(EmbreeScene&& other) noexcept;

    [[nodiscard]] RTCScene get() const noexcept { return scene_; }

private:
    RTCScene scene_ = nullptr;
};

class EmbreeGeometry {
public:
    // Throws std::runtime_error (via device.check) if Embree cannot create the geometry.
    EmbreeGeometry(const EmbreeDevice& device, RTCGeometryType type);
    ~EmbreeGeometry();
    EmbreeGeometry(const EmbreeGeometry&) = delete;
    EmbreeGeometry& operator=(const EmbreeGeometry&) = delete;
    EmbreeGeometry(EmbreeGeometry&& other) noexcept;
    EmbreeGeometry& operator=(EmbreeGeometry&& other) noexcept;

    [[nodiscard]] RTCGeometry get() const noexcept { return geometry_; }

private:
    RTCGeometry geometry_ = nullptr;
};

}  // namespace mogao
