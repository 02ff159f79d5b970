// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/scene/scene_file.h"

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "renderfarm/scene/mesh_io.h"
#include "renderfarm/scene/procedural.h"

namespace mogao {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

constexpr double kMaxCoordinate = 1e9;  // metres; beyond this float BLAS + double rebasing lose meaning
constexpr std::size_t kMaxInstances = 1'000'000;
constexpr std::size_t kMaxAnimationSteps = 4096;  // per light: a cue list, not a recorded signal

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// Reads typed fields and turns every problem into a SceneError naming file and field.
class FieldReader {
public:
    explicit FieldReader(std::string origin) : origin_(std::move(origin)) {}

    [[noreturn]] void fail(const std::string& field, const std::string& what) const {
        throw SceneError(fmt::format("{}: {}: {}", origin_, field, what));
    }

    const json& member(const json& object, const std::string& field, const char* key) const {
        if (!object.is_object()) fail(field, "expected an object");
        auto it = object.find(key);
        if (it == object.end()) fail(field + "." + key, "missing");
        return *it;
    }

    double number(const json& value, const std::string& field, double lo, double hi) const {
        if (!value.is_number()) fail(field, "expected a number");
        const double v = value.get<double>();
        if (!std::isfinite(v) || v < lo || v > hi) fail(field, fmt::format("{} is outside [{}, {}]", v, lo, hi));
        return v;
    }
    double number_or(const json& object, const std::string& field, const char* key, double fallback, double lo,
                     double hi) const {
        auto it = object.find(key);
        return it == object.end() ? fallback : number(*it, field + "." + key, lo, hi);
    }
    int integer_or(const json& object, const std::string& field, const char* key, int fallback, int lo, int hi) const {
        auto it = object.find(key);
        if (it == object.end()) return fallback;
        if (!it->is_number_integer()) fail(field + "." + key, "expected an integer");
        return static_cast<int>(number(*it, field + "." + key, lo, hi));
    }
    bool boolean_or(const json& object, const std::string& field, const char* key, bool fallback) const {
        auto it = object.find(key);
        if (it == object.end()) return fallback;
        if (!it->is_boolean()) fail(field + "." + key, "expected true or false");
        return it->get<bool>();
    }
    std::string string(const json& value, const std::string& field) const {
        if (!value.is_string()) fail(field, "expected a string");
        return value.get<std::string>();
    }
    Eigen::Vector3d vec3(const json& value, const std::string& field, double lo, double hi) const {
        if (!value.is_array() || value.size() != 3) fail(field, "expected an array of 3 numbers");
        return {number(value[0], field + "[0]", lo, hi), number(value[1], field + "[1]", lo, hi),
                number(value[2], field + "[2]", lo, hi)};
    }
    Eigen::Vector3d vec3_or(const json& object, const std::string& field, const char* key, Eigen::Vector3d fallback,
                            double lo, double hi) const {
        auto it = object.find(key);
        return it == object.end() ? fallback : vec3(*it, field + "." + key, lo, hi);
    }
    Rgb colour_or(const json& object, const std::string& field, const char* key, Rgb fallback, double hi) const {
        auto it = object.find(key);
        if (it == object.end()) return fallback;
        if (it->is_number()) {
            const auto v = static_cast<float>(number(*it, field + "." + key, 0, hi));
            return {v, v, v};
        }
        return vec3(*it, field + "." + key, 0, hi).cast<float>();
    }
    void only_keys(const json& object, const std::string& field, std::initializer_list<const char*> keys) const {
        for (auto it = object.begin(); it != object.end(); ++it) {
            bool known = false;
            for (const char* k : keys) known = known || it.key() == k;
            if (!known) {
                std::string list;
                for (const char* k : keys) list += fmt::format("{}{}", list.empty() ? "" : ", ", k);
                fail(field + "." + it.key(), "unknown key (expected one of: " + list + ")");
            }
        }
    }

private:
    std::string origin_;
};

Eigen::Matrix3d rotation_xyz_deg(const Eigen::Vector3d& deg) {
    const double k = std::numbers::pi / 180;
    // Applied about x first, then y, then z (fixed world axes): R = Rz * Ry * Rx.
    return (Eigen::AngleAxisd(deg.z() * k, Eigen::Vector3d::UnitZ()) *
            Eigen::AngleAxisd(deg.y() * k, Eigen::Vector3d::UnitY()) *
            Eigen::AngleAxisd(deg.x() * k, Eigen::Vector3d::UnitX()))
        .toRotationMatrix();
}

std::string expand_scans(const std::string& path, const std::filesystem::path& scans) {
    static const std::string kToken = "{scans}";
    std::string out = path;
    if (auto pos = out.find(kToken); pos != std::string::npos) out.replace(pos, kToken.size(), scans.string());
    return out;
}

class SceneParser {
public:
    SceneParser(const std::filesystem::path& origin, const SceneLoadOptions& options, SceneLoadReport* report)
        : origin_(origin), fields_(origin.string()), scans_(resolve_scans_dir(origin, options)), report_(report) {}

    Scene parse(const json& root) {
        if (!root.is_object()) fields_.fail("(root)", "expected a JSON object");
        fields_.only_keys(root, "(root)",
                          {"name", "exposure", "tone_map", "robust_intersection", "meshes", "materials", "objects",
                           "lights", "viewer"});
        scene_.source = origin_.string();
        scene_.exposure = static_cast<float>(fields_.number_or(root, "(root)", "exposure", 1.0, 1e-6, 1e6));
        if (root.contains("tone_map")) scene_.tone_map = parse_tone_map_field(root["tone_map"]);
        scene_.robust_intersection = fields_.boolean_or(root, "(root)", "robust_intersection", false);
        parse_meshes(fields_.member(root, "(root)", "meshes"));
        parse_materials(root.contains("materials") ? root["materials"] : json::object());
        parse_objects(fields_.member(root, "(root)", "objects"));
        if (root.contains("lights")) parse_lights(root["lights"]);
        if (root.contains("viewer")) parse_viewer(root["viewer"]);
        return std::move(scene_);
    }

private:
    ToneMap parse_tone_map_field(const json& value) {
        const std::string name = fields_.string(value, "tone_map");
        if (name == "clamp") return ToneMap::clamp;
        if (name == "reinhard") return ToneMap::reinhard;
        if (name == "aces") return ToneMap::aces;
        fields_.fail("tone_map", fmt::format("'{}' is not one of clamp, reinhard, aces", name));
    }

    void parse_meshes(const json& meshes) {
        if (!meshes.is_object() || meshes.empty())
            fields_.fail("meshes", "expected a non-empty object of named meshes");
        for (auto it = meshes.begin(); it != meshes.end(); ++it) {
            const std::string field = "meshes." + it.key();
            const auto start = Clock::now();
            Mesh mesh = make_mesh(it.value(), field);
            if (mesh.normals.empty()) compute_vertex_normals(mesh);
            // Keep float coordinates small: the bounding-box centre moves into the transforms.
            const Eigen::Vector3d centre = recentre_mesh(mesh);
            if (report_)
                report_->meshes.push_back(
                    {it.key(), mesh.source, mesh.triangle_count(), mesh.positions.size(), seconds_since(start)});
            mesh_index_[it.key()] = scene_.meshes.size();
            mesh_centre_.push_back(centre);
            scene_.meshes.push_back(std::move(mesh));
        }
    }

    Mesh make_mesh(const json& spec, const std::string& field) {
        if (!spec.is_object()) fields_.fail(field, "expected an object with \"file\" or \"procedural\"");
        if (spec.contains("file")) {
            fields_.only_keys(spec, field, {"file"});
            std::filesystem::path path = expand_scans(fields_.string(spec["file"], field + ".file"), scans_);
            if (path.is_relative()) path = origin_.parent_path() / path;
            if (!std::filesystem::exists(path))
                fields_.fail(field + ".file",
                             fmt::format("{} does not exist{}", path.string(),
                                         spec["file"].get<std::string>().find("{scans}") != std::string::npos
                                             ? " (set MOGAO_SCANS_DIR or --scans to the scans folder)"
                                             : ""));
            try {
                return load_mesh(path);
            } catch (const std::exception& e) {
                fields_.fail(field + ".file", e.what());
            }
        }
        const std::string kind = fields_.string(fields_.member(spec, field, "procedural"), field + ".procedural");
        try {
            if (kind == "grotto_room") {
                fields_.only_keys(spec, field,
                                  {"procedural", "radius", "height", "dome_height", "entrance_deg", "segments", "rings",
                                   "roughness", "seed"});
                GrottoRoomParams p;
                p.radius = fields_.number_or(spec, field, "radius", p.radius, -1e300, 1e300);
                p.height = fields_.number_or(spec, field, "height", p.height, -1e300, 1e300);
                p.dome_height = fields_.number_or(spec, field, "dome_height", p.dome_height, -1e300, 1e300);
                p.entrance_deg = fields_.number_or(spec, field, "entrance_deg", p.entrance_deg, -1e300, 1e300);
                p.segments = fields_.integer_or(spec, field, "segments", p.segments, 0, 1 << 30);
                p.rings = fields_.integer_or(spec, field, "rings", p.rings, 0, 1 << 30);
                p.roughness = fields_.number_or(spec, field, "roughness", p.roughness, -1e300, 1e300);
                p.seed = static_cast<std::uint32_t>(
                    fields_.integer_or(spec, field, "seed", static_cast<int>(p.seed), 0, 1 << 30));
                return make_grotto_room(p);
            }
            if (kind == "box") {
                fields_.only_keys(spec, field, {"procedural", "size"});
                const Eigen::Vector3d s =
                    fields_.vec3(fields_.member(spec, field, "size"), field + ".size", -1e300, 1e300);
                return make_box(s.x(), s.y(), s.z());
            }
            if (kind == "uv_sphere") {
                fields_.only_keys(spec, field, {"procedural", "radius", "segments", "rings"});
                return make_uv_sphere(fields_.number_or(spec, field, "radius", 1.0, -1e300, 1e300),
                                      fields_.integer_or(spec, field, "segments", 64, 0, 1 << 30),
                                      fields_.integer_or(spec, field, "rings", 32, 0, 1 << 30));
            }
            if (kind == "ground_plane") {
                fields_.only_keys(spec, field, {"procedural", "size", "subdivisions"});
                return make_ground_plane(fields_.number_or(spec, field, "size", 10.0, -1e300, 1e300),
                                         fields_.integer_or(spec, field, "subdivisions", 1, 0, 1 << 30));
            }
        } catch (const std::invalid_argument& e) {
            fields_.fail(field, e.what());
        }
        fields_.fail(field + ".procedural",
                     fmt::format("unknown kind \"{}\" (expected grotto_room, box, uv_sphere or ground_plane)", kind));
    }

    void parse_materials(const json& materials) {
        if (!materials.is_object()) fields_.fail("materials", "expected an object of named materials");
        scene_.materials.push_back(Material{"default"});
        material_index_["default"] = 0;
        for (auto it = materials.begin(); it != materials.end(); ++it) {
            const std::string field = "materials." + it.key();
            const json& m = it.value();
            if (!m.is_object()) fields_.fail(field, "expected an object");
            fields_.only_keys(m, field, {"albedo", "specular", "shininess"});
            Material material{it.key()};
            material.albedo = fields_.colour_or(m, field, "albedo", material.albedo, 1.0);
            material.specular = fields_.colour_or(m, field, "specular", material.specular, 1.0);
            material.shininess =
                static_cast<float>(fields_.number_or(m, field, "shininess", material.shininess, 1, 1e5));
            material_index_[it.key()] = scene_.materials.size();
            if (it.key() == "default") scene_.materials[0] = material;
            else scene_.materials.push_back(material);
        }
    }

    // object_to_world = T * R * S, applied to the file's coordinates. anchor "base" shifts the
    // object so that the bottom-centre of its (scaled, rotated) bounding box lands on translate.
    Eigen::Affine3d parse_transform(const json& t, const std::string& field, std::size_t mesh) {
        if (!t.is_object()) fields_.fail(field, "expected an object");
        fields_.only_keys(t, field, {"scale", "rotate_deg", "translate", "anchor"});
        Eigen::Vector3d scale(1, 1, 1);
        if (auto it = t.find("scale"); it != t.end()) {
            if (it->is_number()) scale.setConstant(fields_.number(*it, field + ".scale", 1e-9, 1e9));
            else scale = fields_.vec3(*it, field + ".scale", 1e-9, 1e9);
        }
        const Eigen::Matrix3d linear =
            rotation_xyz_deg(fields_.vec3_or(t, field, "rotate_deg", Eigen::Vector3d::Zero(), -1e6, 1e6)) *
            scale.asDiagonal();
        Eigen::Vector3d translate =
            fields_.vec3_or(t, field, "translate", Eigen::Vector3d::Zero(), -kMaxCoordinate, kMaxCoordinate);
        const std::string anchor = t.contains("anchor") ? fields_.string(t["anchor"], field + ".anchor") : "origin";
        if (anchor == "base") {
            Eigen::AlignedBox3d box;
            for (const Eigen::Vector3f& p : scene_.meshes[mesh].positions)
                box.extend(linear * (p.cast<double>() + mesh_centre_[mesh]));
            translate -= Eigen::Vector3d(box.center().x(), box.min().y(), box.center().z());
        } else if (anchor != "origin") {
            fields_.fail(field + ".anchor", "expected \"origin\" or \"base\"");
        }
        Eigen::Affine3d m = Eigen::Affine3d::Identity();
        m.linear() = linear;
        m.translation() = translate;
        return m;
    }

    void parse_objects(const json& objects) {
        if (!objects.is_array() || objects.empty()) fields_.fail("objects", "expected a non-empty array");
        for (std::size_t i = 0; i < objects.size(); ++i) {
            const std::string field = fmt::format("objects[{}]", i);
            const json& o = objects[i];
            if (!o.is_object()) fields_.fail(field, "expected an object");
            fields_.only_keys(o, field, {"name", "mesh", "material", "transform", "ring"});
            Instance instance;
            instance.name = o.contains("name") ? fields_.string(o["name"], field + ".name") : field;
            const std::string mesh_name = fields_.string(fields_.member(o, field, "mesh"), field + ".mesh");
            auto mesh = mesh_index_.find(mesh_name);
            if (mesh == mesh_index_.end())
                fields_.fail(field + ".mesh", "no mesh named \"" + mesh_name + "\" in meshes");
            instance.mesh = mesh->second;
            const std::string material_name =
                o.contains("material") ? fields_.string(o["material"], field + ".material") : "default";
            auto material = material_index_.find(material_name);
            if (material == material_index_.end())
                fields_.fail(field + ".material", "no material named \"" + material_name + "\" in materials");
            instance.material = material->second;
            const Eigen::Affine3d placed = o.contains("transform")
                                               ? parse_transform(o["transform"], field + ".transform", instance.mesh)
                                               : Eigen::Affine3d::Identity();
            // The mesh was re-centred on load: put its centre back before the object's transform.
            const Eigen::Affine3d to_file = Eigen::Affine3d(Eigen::Translation3d(mesh_centre_[instance.mesh]));
            if (o.contains("ring")) add_ring(instance, placed * to_file, o["ring"], field + ".ring");
            else add_instance(std::move(instance), placed * to_file, field);
        }
    }

    void add_instance(Instance instance, const Eigen::Affine3d& transform, const std::string& field) {
        if (scene_.instances.size() >= kMaxInstances)
            fields_.fail(field, fmt::format("more than {} instances", kMaxInstances));
        instance.object_to_world = transform;
        scene_.instances.push_back(std::move(instance));
    }

    // Copies of an object around the room's axis (statues in wall niches): count per tier, spread
    // evenly over [start_deg, end_deg] (0 = +z, toward +x), at `radius`, one tier per height, each
    // copy turned to face the axis.
    void add_ring(const Instance& prototype, const Eigen::Affine3d& local, const json& ring, const std::string& field) {
        if (!ring.is_object()) fields_.fail(field, "expected an object");
        fields_.only_keys(ring, field, {"count", "radius", "start_deg", "end_deg", "heights"});
        const int count = fields_.integer_or(ring, field, "count", 8, 1, 100000);
        const double radius =
            fields_.number(fields_.member(ring, field, "radius"), field + ".radius", 0, kMaxCoordinate);
        const double start = fields_.number_or(ring, field, "start_deg", 0, -720, 720);
        const double end = fields_.number_or(ring, field, "end_deg", 360.0 * (count - 1) / count, -720, 720);
        std::vector<double> heights{0.0};
        if (ring.contains("heights")) {
            const json& h = ring["heights"];
            if (!h.is_array() || h.empty()) fields_.fail(field + ".heights", "expected a non-empty array of numbers");
            heights.clear();
            for (std::size_t k = 0; k < h.size(); ++k)
                heights.push_back(
                    fields_.number(h[k], fmt::format("{}.heights[{}]", field, k), -kMaxCoordinate, kMaxCoordinate));
        }
        const double k = std::numbers::pi / 180;
        for (std::size_t tier = 0; tier < heights.size(); ++tier) {
            for (int i = 0; i < count; ++i) {
                const double deg = count == 1 ? start : start + (end - start) * i / (count - 1);
                const double theta = deg * k;
                Eigen::Affine3d place = Eigen::Affine3d::Identity();
                place.translation() =
                    Eigen::Vector3d(radius * std::sin(theta), heights[tier], radius * std::cos(theta));
                // Objects face +z in their own frame; turn them to face the axis.
                place.linear() =
                    Eigen::AngleAxisd(theta + std::numbers::pi, Eigen::Vector3d::UnitY()).toRotationMatrix();
                Instance copy = prototype;
                copy.name = fmt::format("{}#{}.{}", prototype.name, tier, i);
                add_instance(std::move(copy), place * local, field);
            }
        }
    }

    // A light's optional "animation": {"step_s": seconds per step, "scale": [factor per step, ...]}.
    void parse_animation(const json& light, const std::string& field, LightKind kind, std::size_t index) {
        auto it = light.find("animation");
        if (it == light.end()) return;
        LightAnimation a;
        const std::string where = field + ".animation";
        if (!it->is_object()) fields_.fail(where, "expected an object {\"step_s\": ..., \"scale\": [...]}");
        fields_.only_keys(*it, where, {"step_s", "scale"});
        a.step_s = fields_.number(fields_.member(*it, where, "step_s"), where + ".step_s", 1e-3, 1e6);
        const json& scale = fields_.member(*it, where, "scale");
        if (!scale.is_array() || scale.empty() || scale.size() > kMaxAnimationSteps)
            fields_.fail(where + ".scale", fmt::format("expected an array of 1 to {} numbers", kMaxAnimationSteps));
        for (std::size_t i = 0; i < scale.size(); ++i)
            a.scale.push_back(
                static_cast<float>(fields_.number(scale[i], fmt::format("{}.scale[{}]", where, i), 0, 1e6)));
        scene_.animated_lights.push_back({kind, index, std::move(a)});
    }

    void parse_lights(const json& lights) {
        if (!lights.is_array()) fields_.fail("lights", "expected an array");
        for (std::size_t i = 0; i < lights.size(); ++i) {
            const std::string field = fmt::format("lights[{}]", i);
            const json& l = lights[i];
            const std::string type = fields_.string(fields_.member(l, field, "type"), field + ".type");
            if (type == "sun") {
                fields_.only_keys(l, field, {"type", "direction_to_light", "irradiance", "cast_shadows", "animation"});
                DirectionalLight sun;
                const Eigen::Vector3d d = fields_.vec3(fields_.member(l, field, "direction_to_light"),
                                                       field + ".direction_to_light", -1e6, 1e6);
                if (d.norm() < 1e-9) fields_.fail(field + ".direction_to_light", "must not be the zero vector");
                sun.direction_to_light = d.normalized();
                sun.irradiance = fields_.colour_or(l, field, "irradiance", sun.irradiance, 1e6);
                sun.cast_shadows = fields_.boolean_or(l, field, "cast_shadows", true);
                parse_animation(l, field, LightKind::sun, scene_.directional_lights.size());
                scene_.directional_lights.push_back(sun);
            } else if (type == "point") {
                fields_.only_keys(l, field, {"type", "position", "intensity", "cast_shadows", "animation"});
                PointLight point;
                point.position = fields_.vec3(fields_.member(l, field, "position"), field + ".position",
                                              -kMaxCoordinate, kMaxCoordinate);
                point.intensity = fields_.colour_or(l, field, "intensity", point.intensity, 1e9);
                point.cast_shadows = fields_.boolean_or(l, field, "cast_shadows", true);
                parse_animation(l, field, LightKind::point, scene_.point_lights.size());
                scene_.point_lights.push_back(point);
            } else if (type == "area") {
                fields_.only_keys(l, field,
                                  {"type", "corner", "edge_u", "edge_v", "radiance", "cast_shadows", "animation"});
                AreaLight area;
                area.corner = fields_.vec3(fields_.member(l, field, "corner"), field + ".corner", -kMaxCoordinate,
                                           kMaxCoordinate);
                area.edge_u = fields_.vec3(fields_.member(l, field, "edge_u"), field + ".edge_u", -1e6, 1e6);
                area.edge_v = fields_.vec3(fields_.member(l, field, "edge_v"), field + ".edge_v", -1e6, 1e6);
                if (area.edge_u.cross(area.edge_v).norm() < 1e-12)
                    fields_.fail(field, "edge_u and edge_v must span a non-zero area");
                area.radiance = fields_.colour_or(l, field, "radiance", area.radiance, 1e9);
                area.cast_shadows = fields_.boolean_or(l, field, "cast_shadows", true);
                parse_animation(l, field, LightKind::area, scene_.area_lights.size());
                scene_.area_lights.push_back(area);
            } else if (type == "environment") {
                fields_.only_keys(l, field, {"type", "radiance"});
                EnvironmentLight env;
                env.radiance = fields_.colour_or(l, field, "radiance", env.radiance, 1e6);
                scene_.environment_lights.push_back(env);
            } else {
                fields_.fail(field + ".type",
                             "unknown light type \"" + type + "\" (expected sun, point, area or environment)");
            }
        }
    }

    void parse_viewer(const json& v) {
        if (!v.is_object()) fields_.fail("viewer", "expected an object");
        fields_.only_keys(v, "viewer", {"eye_height", "start", "start_yaw_deg", "visitable"});
        scene_.viewer.eye_height_m =
            fields_.number_or(v, "viewer", "eye_height", scene_.viewer.eye_height_m, 0.01, 100);
        scene_.viewer.start =
            fields_.vec3_or(v, "viewer", "start", scene_.viewer.start, -kMaxCoordinate, kMaxCoordinate);
        scene_.viewer.start_yaw_deg = fields_.number_or(v, "viewer", "start_yaw_deg", 0, -3600, 3600);
        if (v.contains("visitable")) scene_.viewer.visitable = parse_visitable(v["visitable"]);
    }

    // "visitable": { "min": [x, z], "max": [x, z] } or { "centre": [x, z], "radius": r }, with
    // "eye_height": [low, high] (the eye's world y), metres.
    VisitableArea parse_visitable(const json& v) const {
        const std::string field = "viewer.visitable";
        fields_.only_keys(v, field, {"min", "max", "centre", "radius", "eye_height"});
        const auto pair = [&](const char* key) {
            const json& a = fields_.member(v, field, key);
            if (!a.is_array() || a.size() != 2) fields_.fail(field + "." + key, "expected an array of two numbers");
            return Eigen::Vector2d(fields_.number(a[0], field + "." + key + "[0]", -kMaxCoordinate, kMaxCoordinate),
                                   fields_.number(a[1], field + "." + key + "[1]", -kMaxCoordinate, kMaxCoordinate));
        };
        VisitableArea area;
        const Eigen::Vector2d start(scene_.viewer.start.x(), scene_.viewer.start.z());
        bool inside = false;
        if (v.contains("radius")) {
            if (v.contains("min") || v.contains("max"))
                fields_.fail(field, "either min/max or centre/radius, not both");
            area.centre_xz = pair("centre");
            area.radius_m = fields_.number(v["radius"], field + ".radius", 0.01, kMaxCoordinate);
            inside = (start - area.centre_xz).norm() <= area.radius_m;
        } else {
            area.min_xz = pair("min");
            area.max_xz = pair("max");
            if (!(area.min_xz.array() <= area.max_xz.array()).all())
                fields_.fail(field, "min must not exceed max in x or z");
            inside = (start.array() >= area.min_xz.array()).all() && (start.array() <= area.max_xz.array()).all();
        }
        const Eigen::Vector2d eye = pair("eye_height");
        area.eye_min_m = eye.x();
        area.eye_max_m = eye.y();
        if (!(area.eye_min_m <= area.eye_max_m)) fields_.fail(field + ".eye_height", "low must not exceed high");
        if (!inside) fields_.fail(field, "viewer.start lies outside the visitable area");
        return area;
    }

    std::filesystem::path origin_;
    FieldReader fields_;
    std::filesystem::path scans_;
    SceneLoadReport* report_;
    Scene scene_;
    std::map<std::string, std::size_t> mesh_index_;
    std::vector<Eigen::Vector3d> mesh_centre_;
    std::map<std::string, std::size_t> material_index_;
};

}  // namespace

std::filesystem::path resolve_scans_dir(const std::filesystem::path& scene_file, const SceneLoadOptions& options) {
    // Absolute, so that "{scans}/x.obj" is not joined to the scene's folder a second time.
    if (!options.scans_dir.empty()) return std::filesystem::absolute(options.scans_dir);
    if (const char* env = std::getenv("MOGAO_SCANS_DIR"); env && *env) return std::filesystem::absolute(env);
    return std::filesystem::absolute(scene_file.parent_path() / ".." / ".." / "shared" / "data" / "scans")
        .lexically_normal();
}

Scene parse_scene(const std::string& json_text, const std::filesystem::path& origin, const SceneLoadOptions& options,
                  SceneLoadReport* report) {
    const auto start = Clock::now();
    json root;
    try {
        root = json::parse(json_text);
    } catch (const json::parse_error& e) {
        throw SceneError(fmt::format("{}: not valid JSON: {}", origin.string(), e.what()));
    } catch (const json::out_of_range& e) {  // 1e999: beyond double range (would be infinite)
        throw SceneError(fmt::format("{}: number out of range (beyond ±1.8e308): {}", origin.string(), e.what()));
    }
    Scene scene = SceneParser(origin, options, report).parse(root);
    if (report) {
        report->instanced_triangles = scene.triangle_count();
        report->seconds = seconds_since(start);
    }
    return scene;
}

Scene load_scene(const std::filesystem::path& file, const SceneLoadOptions& options, SceneLoadReport* report) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw SceneError(fmt::format("{}: cannot open scene file", file.string()));
    std::ostringstream text;
    text << in.rdbuf();
    return parse_scene(text.str(), file, options, report);
}

}  // namespace mogao
