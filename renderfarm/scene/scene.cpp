// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/scene/scene.h"

namespace mogao {

std::size_t Scene::triangle_count() const {
    std::size_t total = 0;
    for (const Instance& instance : instances) total += meshes.at(instance.mesh).triangle_count();
    return total;
}

}  // namespace mogao
