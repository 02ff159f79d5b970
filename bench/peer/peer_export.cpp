// SPDX-License-Identifier: Apache-2.0
#include "bench/peer/peer_export.h"

#include <cerrno>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <variant>

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

void write_instance(std::ostream& out, const Scene& scene, const Instance& inst, ExportStats& stats) {
    const Mesh& mesh = scene.meshes[inst.mesh];
    const Eigen::Matrix3d normal_matrix = inst.object_to_world.linear().inverse().transpose();
    out << "o " << inst.name << "\nusemtl " << scene.materials[inst.material].name << '\n';
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
    const std::size_t base = stats.vertices + 1;  // OBJ indices are 1-based and global
    for (const auto& t : mesh.triangles) {
        out << 'f';
        for (const std::uint32_t i : t) {
            out << ' ' << base + i;
            if (normals) out << "//" << base + i;
        }
        out << '\n';
    }
    stats.vertices += mesh.positions.size();
    stats.triangles += mesh.triangles.size();
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
    for (const Material& mat : scene.materials)
        m << "newmtl " << mat.name << "\nKd " << mat.albedo.x() << ' ' << mat.albedo.y() << ' ' << mat.albedo.z()
          << "\nKs " << mat.specular.x() << ' ' << mat.specular.y() << ' ' << mat.specular.z() << "\nNs "
          << mat.shininess << "\n\n";
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
    j["materials"] = materials;
    j["lights"] = lights_json(scene);
    j["exposure"] = scene.exposure;
    j["tone_map"] = scene.tone_map == ToneMap::aces       ? "aces"
                    : scene.tone_map == ToneMap::reinhard ? "reinhard"
                                                          : "clamp";
    nlohmann::json unexported = nlohmann::json::array();
    for (const Mesh& mesh : scene.meshes)
        if (!mesh.colors.empty() || mesh.texture != nullptr) unexported.push_back(mesh.source);
    j["meshes_with_colour_not_exported"] = unexported;
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
