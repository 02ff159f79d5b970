#include "renderfarm/trace/embree_scene.h"

#include <utility>

namespace mogao {

EmbreeScene::EmbreeScene(const EmbreeDevice& device) : scene_(rtcNewScene(device.get())) {
    device.check("rtcNewScene");
}

EmbreeScene::~EmbreeScene() {
    if (scene_ != nullptr) rtcReleaseScene(scene_);
}

EmbreeScene::EmbreeScene(EmbreeScene&& other) noexcept : scene_(std::exchange(other.scene_, nullptr)) {}

EmbreeScene& EmbreeScene::operator=(EmbreeScene&& other) noexcept {
    if (this != &other) {
        if (scene_ != nullptr) rtcReleaseScene(scene_);
        scene_ = std::exchange(other.scene_, nullptr);
    }
    return *this;
}

EmbreeGeometry::EmbreeGeometry(const EmbreeDevice& device, RTCGeometryType type)
    : geometry_(rtcNewGeometry(device.get(), type)) {
    device.check("rtcNewGeometry");
}

EmbreeGeometry::~EmbreeGeometry() {
    if (geometry_ != nullptr) rtcReleaseGeometry(geometry_);
}

EmbreeGeometry::EmbreeGeometry(EmbreeGeometry&& other) noexcept
    : geometry_(std::exchange(other.geometry_, nullptr)) {}

EmbreeGeometry& EmbreeGeometry::operator=(EmbreeGeometry&& other) noexcept {
    if (this != &other) {
        if (geometry_ != nullptr) rtcReleaseGeometry(geometry_);
        geometry_ = std::exchange(other.geometry_, nullptr);
    }
    return *this;
}

}  // namespace mogao
