// SPDX-License-Identifier: Apache-2.0
// Reading the base-colour texture of a mesh file through assimp's materials (used by load_mesh).
#pragma once

#include <filesystem>
#include <memory>
#include <vector>

#include <assimp/scene.h>

#include "renderfarm/scene/texture.h"

namespace mogao {

// The base-colour texture shared by the materials `used` (indices into scene.mMaterials) of the
// meshes merged from `path`: glTF baseColorTexture (aiTextureType_BASE_COLOR) or, for other
// formats, the diffuse map (aiTextureType_DIFFUSE, e.g. OBJ map_Kd). The image is a file beside
// `path` (relative URIs resolve against its folder) or embedded ("*N", glb), JPEG or PNG; its
// wrap modes come from the material (glTF sampler wrapS/wrapT; clamp for clamp-to-edge and
// mirrored repeat is read as repeat). Returns null when no used material has one.
// Throws MeshLoadError (file = path) when the materials name different textures (one texture
// per mesh file is supported), or the image is missing, not JPEG/PNG, or fails to decode.
[[nodiscard]] std::shared_ptr<const Texture> load_base_color_texture(const aiScene& scene,
                                                                     const std::vector<unsigned>& used,
                                                                     const std::filesystem::path& path);

}  // namespace mogao
