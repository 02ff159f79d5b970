// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/trace/embree_scene.h"

namespace mogao {

// A failed rtcNew* returns nullptr, which the member holds as "owns nothing" while check() throws.
EmbreeScene::EmbreeScene(const EmbreeDevice& device) : scene_(rtcNewScene(device.get())) {
    device.check("rtcNewScene");
}

EmbreeGeometry::EmbreeGeometry(const EmbreeDevice& device, RTCGeometryType type)
    : geometry_(rtcNewGeometry(device.get(), type)) {
    device.check("rtcNewGeometry");
}

}  // namespace mogao
