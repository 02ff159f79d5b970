// SPDX-License-Identifier: Apache-2.0
#include "bench/peer/peer_export.h"

#include <cerrno>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <variant>

#include "common/png_io.h"
#include "renderfarm/trace/camera.h"
#include "renderfarm/trace/shading.h"

#include <nlohmann/json.hpp>

namespace mogao::peer {
namespace {

// 9 significant digits: sub-micrometre at the grotto's 10 m scale, and a float round-trips.
std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return buf;
}

bool is_textured(const Mesh& mesh) { return mesh.texture != nullptr && mesh.uvs.size() == mesh.positions.size(); }

// A textured instance's material: its material with the mesh's texture, one per (material, mesh).
std::string textured_material_name(const Scene& scene, const Instance& inst) {
    return scene.materials[inst.material].name + "__texture" + std::to_string(inst.mesh);
}

std::string texture_file(std::size_t mesh) { return "texture" + std::to_string(mesh) + ".png"; }

void write_instance(std::ostream& out, const Scene& scene, const Instance& inst, ExportStats& stats) {
    const Mesh& mesh = scene.meshes[inst.mesh];
    const Eigen::Matrix3d normal_matrix = inst.object_to_world.linear().inverse().transpose();
    const bool textured = is_textured(mesh);
    out << "o " << inst.name << "\nusemtl "
        << (textured ? textured_material_name(scene, inst) : scene.materials[inst.material].name) << '\n';
    for (const Eigen::Vector3f& p : mesh.positions) {
        const Eigen::Vector3d w = inst.object_to_world * (mesh.origin + p.cast<double>());
        out << "v " << num(w.x()) << ' ' << num(w.y()) << ' ' << num(w.z()) << '\n';
        stats.lo = stats.lo.cwiseMin(w);
        stats.hi = stats.hi.cwiseMax(w);
    }
    const bool normals = mesh.normals.size() == mesh.positions.size();
    if (normals) {
        for (const Eigen::Vector3f& n : mesh.normals) {
            const Eigen::Vector3d w = (normal_matrix * n.cast<double>()).normalized();
            out << "vn " << num(w.x()) << ' ' << num(w.y()) << ' ' << num(w.z()) << '\n';
        }
    }
    if (textured) {
        // OBJ's v points up the image, ours down (texture.h): v_obj = 1 - v.
        for (const Eigen::Vector2f& uv : mesh.uvs) out << "vt " << num(uv.x()) << ' ' << num(1.0 - uv.y()) << '\n';
    }
    const std::size_t base = stats.vertices + 1;  // OBJ indices are 1-based and global
    const std::size_t uv_base = stats.uvs + 1;
    for (const auto& t : mesh.triangles) {
        out << 'f';
        for (const std::uint32_t i : t) {
            out << ' ' << base + i;
            if (textured) out << '/' << uv_base + i;
            if (normals) out << (textured ? "/" : "//") << base + i;
        }
        out << '\n';
    }
    if (textured) stats.uvs += mesh.uvs.size();
    stats.vertices += mesh.positions.size();
    stats.triangles += mesh.triangles.size();
}

struct TexturedUse {
    std::size_t material = 0;
    std::size_t mesh = 0;
};

// Every (material, textured mesh) pair the instances use, by its exported material name.
std::map<std::string, TexturedUse> textured_materials(const Scene& scene) {
    std::map<std::string, TexturedUse> uses;
    for (const Instance& inst : scene.instances)
        if (is_textured(scene.meshes[inst.mesh]))
            uses[textured_material_name(scene, inst)] = {inst.material, inst.mesh};
    return uses;
}

}  // namespace

Result<ExportStats> write_obj(const Scene& scene, const std::filesystem::path& dir) {
    const std::filesystem::path obj = dir / "scene.obj", mtl = dir / "scene.mtl";
    std::ofstream out(obj);
    if (!out) return errno_error("cannot write " + obj.string());
    out << "# " << scene.source << " as loaded by mogao (world metres, +y up)\nmtllib scene.mtl\n";
    ExportStats stats;
    // Normals are written with the same global index as their vertex, so every instance writes its vn
    // (or none, then its faces carry no normal index): keep the vn count equal to the v count.
    for (const Instance& inst : scene.instances) {
        const Mesh& mesh = scene.meshes[inst.mesh];
        if (!mesh.normals.empty() && mesh.normals.size() != mesh.positions.size())
            return make_error(EINVAL, mesh.source + ": normals and positions differ in count");
        write_instance(out, scene, inst, stats);
    }
    if (!out.flush()) return errno_error("cannot write " + obj.string());
    std::ofstream m(mtl);
    if (!m) return errno_error("cannot write " + mtl.string());
    const auto write_material = [&m](const Material& mat, const std::string& name, const std::string& map_kd) {
        m << "newmtl " << name << "\nKd " << mat.albedo.x() << ' ' << mat.albedo.y() << ' ' << mat.albedo.z() << "\nKs "
          << mat.specular.x() << ' ' << mat.specular.y() << ' ' << mat.specular.z() << "\nNs " << mat.shininess << '\n';
        if (!map_kd.empty()) m << "map_Kd " << map_kd << '\n';
        m << '\n';
    };
    for (const Material& mat : scene.materials) write_material(mat, mat.name, "");
    for (const auto& [name, use] : textured_materials(scene)) {
        write_material(scene.materials[use.material], name, texture_file(use.mesh));
        if (!stats.textures_written.contains(use.mesh)) {
            try {
                write_png(dir / texture_file(use.mesh), scene.meshes[use.mesh].texture->image);
            } catch (const std::exception& e) {
                return make_error(EIO, e.what());
            }
            stats.textures_written.insert(use.mesh);
        }
    }
    if (!m.flush()) return errno_error("cannot write " + mtl.string());
    return stats;
}

namespace {

nlohmann::json to_json(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
nlohmann::json to_json(const Rgb& c) { return {c.x(), c.y(), c.z()}; }

nlohmann::json lights_json(const Scene& scene) {
    nlohmann::json lights = nlohmann::json::array();
    for (const PointLight& l : scene.point_lights)
        lights.push_back({{"type", "point"},
                          {"position", to_json(l.position)},
                          {"intensity", to_json(l.intensity)},
                          {"cast_shadows", l.cast_shadows}});
    for (const DirectionalLight& l : scene.directional_lights)
        lights.push_back({{"type", "sun"},
                          {"direction_to_light", to_json(l.direction_to_light)},
                          {"irradiance", to_json(l.irradiance)},
                          {"cast_shadows", l.cast_shadows}});
    for (const AreaLight& l : scene.area_lights)
        lights.push_back({{"type", "area"},
                          {"corner", to_json(l.corner)},
                          {"edge_u", to_json(l.edge_u)},
                          {"edge_v", to_json(l.edge_v)},
                          {"radiance", to_json(l.radiance)},
                          {"cast_shadows", l.cast_shadows}});
    for (const EnvironmentLight& l : scene.environment_lights)
        lights.push_back({{"type", "environment"}, {"radiance", to_json(l.radiance)}});
    return lights;
}

}  // namespace

Status write_peer_json(const Scene& scene, const ViewRequest& request, const std::filesystem::path& dir) {
    const auto* pinhole = std::get_if<PinholeCamera>(&request.camera);
    if (pinhole == nullptr)
        throw std::invalid_argument(
            "peer export: only a pinhole camera has a Cycles equivalent (not a cylinder screen)");
    const Eigen::Matrix3d r = pose_rotation(request.pose.yaw_deg, request.pose.pitch_deg);
    nlohmann::json j;
    j["source"] = scene.source;
    j["camera"] = {
        {"vertical_fov_deg", pinhole->vertical_fov_deg},
        {"eye", to_json(request.pose.eye)},
        {"rotation_rows",
         {to_json(Eigen::Vector3d(r.row(0))), to_json(Eigen::Vector3d(r.row(1))), to_json(Eigen::Vector3d(r.row(2)))}},
        {"width", request.size.width},
        {"height", request.size.height}};
    nlohmann::json materials = nlohmann::json::object();
    for (const Material& m : scene.materials)
        materials[m.name] = {{"albedo", to_json(m.albedo)},
                             {"specular", to_json(m.specular)},
                             {"shininess", m.shininess},
                             {"ggx_alpha", ggx_alpha_from_shininess(m.shininess)}};
    for (const auto& [name, use] : textured_materials(scene)) {
        const Material& m = scene.materials[use.material];
        const Texture& t = *scene.meshes[use.mesh].texture;
        materials[name] = {{"albedo", to_json(m.albedo)},
                           {"specular", to_json(m.specular)},
                           {"shininess", m.shininess},
                           {"ggx_alpha", ggx_alpha_from_shininess(m.shininess)},
                           {"texture", texture_file(use.mesh)},
                           {"texture_source", t.source},
                           {"wrap",
                            {t.wrap_u == TextureWrap::repeat ? "repeat" : "clamp",
                             t.wrap_v == TextureWrap::repeat ? "repeat" : "clamp"}}};
    }
    j["materials"] = materials;
    j["lights"] = lights_json(scene);
    j["exposure"] = scene.exposure;
    j["tone_map"] = scene.tone_map == ToneMap::aces       ? "aces"
                    : scene.tone_map == ToneMap::reinhard ? "reinhard"
                                                          : "clamp";
    nlohmann::json unexported = nlohmann::json::array();
    for (const Mesh& mesh : scene.meshes)
        if (!mesh.colors.empty()) unexported.push_back(mesh.source);
    j["meshes_with_vertex_colour_not_exported"] = unexported;
    const std::filesystem::path file = dir / "peer.json";
    std::ofstream out(file);
    if (!out) return errno_error("cannot write " + file.string());
    out << j.dump(2) << '\n';
    if (!out.flush()) return errno_error("cannot write " + file.string());
    return {};
}

Result<ExportStats> read_obj_stats(const std::filesystem::path& file) {
    std::ifstream in(file);
    if (!in) return errno_error("cannot read " + file.string());
    ExportStats stats;
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("v ", 0) == 0) {
            std::istringstream s(line.substr(2));
            Eigen::Vector3d p;
            if (!(s >> p.x() >> p.y() >> p.z())) return make_error(EINVAL, file.string() + ": bad line " + line);
            stats.lo = stats.lo.cwiseMin(p);
            stats.hi = stats.hi.cwiseMax(p);
            ++stats.vertices;
        } else if (line.rfind("vt ", 0) == 0) {
            ++stats.uvs;
        } else if (line.rfind("f ", 0) == 0) {
            std::istringstream s(line.substr(2));
            int corners = 0;
            for (std::string c; s >> c;) {
                const long index = std::stol(c);  // stops at the first '/'
                if (index < 1 || static_cast<std::size_t>(index) > stats.vertices)
                    return make_error(EINVAL, file.string() + ": face index out of range in " + line);
                ++corners;
            }
            if (corners != 3) return make_error(EINVAL, file.string() + ": not a triangle: " + line);
            ++stats.triangles;
        }
    }
    return stats;
}

}  // namespace mogao::peer
