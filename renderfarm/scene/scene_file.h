// SPDX-License-Identifier: Apache-2.0
// Reading a scene file (JSON; schema and examples in docs/scene-format.md) into a Scene.
//
// Errors: every problem throws SceneError whose message names the scene file, the JSON field
// (e.g. "objects[3].transform.scale") and the rule or limit that was broken. Mesh files that fail
// to load are reported with the mesh loader's message. Nothing is rendered from a half-read scene:
// load_scene either returns a complete Scene or throws.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "renderfarm/scene/scene.h"

namespace mogao {

struct SceneError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

struct SceneLoadOptions {
    // Replaces "{scans}" in mesh paths. Empty: $MOGAO_SCANS_DIR, else <scene dir>/../../shared/data/scans
    // (the project's layout: the scans live in ../shared beside the checkout, never in the repo).
    std::filesystem::path scans_dir;
};

// Per-mesh figures for the operator: what was loaded, how big, how long it took.
struct MeshLoadFigures {
    std::string name;
    std::string source;
    std::size_t triangles = 0;
    std::size_t vertices = 0;
    double seconds = 0.0;
};

struct SceneLoadReport {
    std::vector<MeshLoadFigures> meshes;
    std::size_t instanced_triangles = 0;  // Scene::triangle_count()
    double seconds = 0.0;                 // whole load, parsing included
};

[[nodiscard]] Scene load_scene(const std::filesystem::path& file, const SceneLoadOptions& options = {},
                               SceneLoadReport* report = nullptr);

// Parses scene JSON text; `origin` names the text in messages and anchors relative mesh paths.
[[nodiscard]] Scene parse_scene(const std::string& json_text, const std::filesystem::path& origin,
                                const SceneLoadOptions& options = {}, SceneLoadReport* report = nullptr);

// Resolves the "{scans}" folder as documented in SceneLoadOptions.
[[nodiscard]] std::filesystem::path resolve_scans_dir(const std::filesystem::path& scene_file,
                                                      const SceneLoadOptions& options);

}  // namespace mogao
