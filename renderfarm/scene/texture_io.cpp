// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/scene/texture_io.h"

#include <fstream>
#include <iterator>
#include <optional>
#include <span>
#include <string>

#include <assimp/material.h>
#include <fmt/format.h>

#include "common/jpeg_codec.h"
#include "common/png_io.h"
#include "renderfarm/scene/mesh_io.h"

namespace mogao {
namespace {

struct TextureRef {
    std::string path;  // as the material names it
    TextureWrap wrap_u = TextureWrap::repeat;
    TextureWrap wrap_v = TextureWrap::repeat;
};

TextureWrap wrap_of(aiTextureMapMode mode) {
    return mode == aiTextureMapMode_Clamp ? TextureWrap::clamp : TextureWrap::repeat;
}

std::optional<TextureRef> base_color_of(const aiMaterial& material) {
    for (const aiTextureType type : {aiTextureType_BASE_COLOR, aiTextureType_DIFFUSE}) {
        if (material.GetTextureCount(type) == 0) continue;
        aiString name;
        aiTextureMapMode modes[2] = {aiTextureMapMode_Wrap, aiTextureMapMode_Wrap};
        if (material.GetTexture(type, 0, &name, nullptr, nullptr, nullptr, nullptr, modes) != AI_SUCCESS) continue;
        return TextureRef{name.C_Str(), wrap_of(modes[0]), wrap_of(modes[1])};
    }
    return std::nullopt;
}

bool is_png(std::span<const std::uint8_t> bytes) {
    static constexpr std::uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    return bytes.size() >= 8 && std::equal(kSignature, kSignature + 8, bytes.begin());
}

Rgb8Image decode_image(std::span<const std::uint8_t> bytes, const std::filesystem::path& png_path,
                       const std::string& name) {
    if (bytes.size() >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF)
        return JpegDecoder().decode(bytes);
    if (is_png(bytes) && !png_path.empty()) return read_png(png_path);
    throw MeshLoadError(name, "texture is neither JPEG nor a PNG file");
}

Rgb8Image read_texture_image(const aiScene& scene, const std::string& ref, const std::filesystem::path& mesh_path) {
    const std::string file = mesh_path.string();
    if (const aiTexture* embedded = scene.GetEmbeddedTexture(ref.c_str()); embedded != nullptr) {
        if (embedded->mHeight != 0)
            throw MeshLoadError(file, fmt::format("embedded texture '{}' is uncompressed (unsupported)", ref));
        const auto* data = reinterpret_cast<const std::uint8_t*>(embedded->pcData);
        return decode_image(std::span<const std::uint8_t>(data, embedded->mWidth), {}, file + "#" + ref);
    }
    const std::filesystem::path image_path = mesh_path.parent_path() / ref;
    std::ifstream in(image_path, std::ios::binary);
    if (!in) throw MeshLoadError(file, fmt::format("texture '{}' not found ({})", ref, image_path.string()));
    const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    return decode_image(bytes, image_path, image_path.string());
}

}  // namespace

std::shared_ptr<const Texture> load_base_color_texture(const aiScene& scene, const std::vector<unsigned>& used,
                                                       const std::filesystem::path& path) {
    const std::string file = path.string();
    std::optional<TextureRef> chosen;
    for (const unsigned m : used) {
        if (m >= scene.mNumMaterials) continue;
        const std::optional<TextureRef> ref = base_color_of(*scene.mMaterials[m]);
        if (!ref) continue;
        if (chosen && chosen->path != ref->path) {
            throw MeshLoadError(file,
                                fmt::format("materials use different base-colour textures ('{}', '{}'); one per mesh "
                                            "file is supported",
                                            chosen->path, ref->path));
        }
        chosen = ref;
    }
    if (!chosen) return nullptr;
    auto texture = std::make_shared<Texture>();
    texture->source = file + ": " + chosen->path;
    texture->wrap_u = chosen->wrap_u;
    texture->wrap_v = chosen->wrap_v;
    try {
        texture->image = read_texture_image(scene, chosen->path, path);
    } catch (const MeshLoadError&) {
        throw;
    } catch (const std::exception& e) {
        throw MeshLoadError(file, fmt::format("texture '{}': {}", chosen->path, e.what()));
    }
    if (texture->image.size.width < 1 || texture->image.size.height < 1) throw MeshLoadError(file, "texture is empty");
    texture->mips = make_mip_chain(texture->image);
    return texture;
}

}  // namespace mogao
