// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/scene/scene_file.h"

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "renderfarm/scene/procedural.h"

namespace mogao {
namespace {

const std::filesystem::path kOrigin = "/nonexistent/test.json";

std::string minimal(const std::string& objects, const std::string& extra = "") {
    return R"({ "meshes": { "ball": { "procedural": "uv_sphere", "radius": 0.5, "segments": 16, "rings": 8 },
                            "box": { "procedural": "box", "size": [1, 2, 3] } },
               "materials": { "red": { "albedo": [0.8, 0.1, 0.1] } },
               "objects": )" +
           objects + extra + "}";
}

// Expects a SceneError whose message contains every fragment.
void expect_error(const std::string& text, std::initializer_list<std::string> fragments) {
    try {
        (void)parse_scene(text, kOrigin);
        FAIL() << "no error for: " << text;
    } catch (const SceneError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(kOrigin.string()), std::string::npos) << message;
        for (const std::string& f : fragments)
            EXPECT_NE(message.find(f), std::string::npos) << "missing '" << f << "' in: " << message;
    }
}

TEST(SceneFile, ParsesMeshesMaterialsObjectsAndLights) {
    const Scene scene = parse_scene(minimal(R"([ { "mesh": "ball", "material": "red" }, { "mesh": "box" } ])",
                                            R"(, "lights": [ { "type": "sun", "direction_to_light": [0, 2, 0] },
                                                           { "type": "environment", "radiance": 0.3 } ],
                                               "viewer": { "eye_height": 1.7, "start": [1, 0, 2] })"),
                                    kOrigin);
    ASSERT_EQ(scene.meshes.size(), 2u);
    ASSERT_EQ(scene.instances.size(), 2u);
    EXPECT_EQ(scene.materials[scene.instances[0].material].name, "red");
    EXPECT_EQ(scene.materials[scene.instances[1].material].name, "default");
    ASSERT_EQ(scene.directional_lights.size(), 1u);
    EXPECT_NEAR(scene.directional_lights[0].direction_to_light.norm(), 1.0, 1e-12);
    ASSERT_EQ(scene.environment_lights.size(), 1u);
    EXPECT_FLOAT_EQ(scene.environment_lights[0].radiance.y(), 0.3f);
    EXPECT_DOUBLE_EQ(scene.viewer.eye_height_m, 1.7);
    EXPECT_EQ(scene.triangle_count(), scene.meshes[0].triangle_count() + scene.meshes[1].triangle_count());
}

// viewer.visitable: where a visitor may stand (the farm's view policy keeps requested eyes in it).
TEST(SceneFile, VisitableAreaIsARectangleOrADiscAroundTheStart) {
    const std::string objects = R"([ { "mesh": "ball" } ])";
    const Scene rect =
        parse_scene(minimal(objects, R"(, "viewer": { "start": [1, 0, 2], "visitable": { "min": [-3, -1], "max": [3, 4],
                                                                             "eye_height": [1, 2] } })"),
                    kOrigin);
    ASSERT_TRUE(rect.viewer.visitable.has_value());
    EXPECT_EQ(rect.viewer.visitable->max_xz, Eigen::Vector2d(3, 4));
    EXPECT_EQ(rect.viewer.visitable->radius_m, 0.0);
    const Scene disc = parse_scene(
        minimal(objects, R"(, "viewer": { "start": [1, 0, 2], "visitable": { "centre": [0, 0], "radius": 6.5,
                                                                             "eye_height": [0.5, 2.5] } })"),
        kOrigin);
    ASSERT_TRUE(disc.viewer.visitable.has_value());
    EXPECT_EQ(disc.viewer.visitable->radius_m, 6.5);
    EXPECT_EQ(disc.viewer.visitable->eye_max_m, 2.5);
    EXPECT_FALSE(parse_scene(minimal(objects), kOrigin).viewer.visitable.has_value());

    expect_error(minimal(objects, R"(, "viewer": { "start": [9, 0, 2], "visitable": { "centre": [0, 0], "radius": 2,
                                                                                      "eye_height": [1, 2] } })"),
                 {"viewer.visitable", "viewer.start lies outside"});
    expect_error(
        minimal(objects, R"(, "viewer": { "visitable": { "min": [1, 1], "max": [0, 9], "eye_height": [1, 2] } })"),
        {"viewer.visitable", "min must not exceed max"});
    expect_error(minimal(objects, R"(, "viewer": { "visitable": { "min": [-1, -1], "max": [1, 9] } })"),
                 {"viewer.visitable.eye_height", "missing"});
    expect_error(minimal(objects, R"(, "viewer": { "visitable": { "centre": [0, 0], "radius": -1,
                                                                   "eye_height": [1, 2] } })"),
                 {"viewer.visitable.radius", "outside"});
}

TEST(SceneFile, ToneMapIsReadAndCheckedByName) {
    EXPECT_EQ(parse_scene(minimal(R"([ { "mesh": "ball" } ])"), kOrigin).tone_map, ToneMap::clamp);
    EXPECT_EQ(parse_scene(minimal(R"([ { "mesh": "ball" } ])", R"(, "tone_map": "aces")"), kOrigin).tone_map,
              ToneMap::aces);
    EXPECT_EQ(parse_scene(minimal(R"([ { "mesh": "ball" } ])", R"(, "tone_map": "reinhard")"), kOrigin).tone_map,
              ToneMap::reinhard);
    expect_error(minimal(R"([ { "mesh": "ball" } ])", R"(, "tone_map": "filmic")"),
                 {"tone_map", "'filmic' is not one of clamp, reinhard, aces"});
    expect_error(minimal(R"([ { "mesh": "ball" } ])", R"(, "tone_map": 3)"), {"tone_map"});
}

TEST(SceneFile, TransformAppliesScaleRotationTranslationInOrder) {
    const Scene scene = parse_scene(
        minimal(
            R"([ { "mesh": "box", "transform": { "scale": 2, "rotate_deg": [0, 90, 0], "translate": [10, 0, 0] } } ])"),
        kOrigin);
    const Eigen::Affine3d& m = scene.instances[0].object_to_world;
    // A file point (1, 0, 0): scaled to (2, 0, 0), turned 90° about +y to (0, 0, -2), moved by +10 x.
    const Eigen::Vector3d p = m * Eigen::Vector3d(1, 0, 0);
    EXPECT_NEAR(p.x(), 10, 1e-12);
    EXPECT_NEAR(p.z(), -2, 1e-12);
}

TEST(SceneFile, BaseAnchorPutsTheBottomCentreOnTheTranslation) {
    const Scene scene = parse_scene(
        minimal(R"([ { "mesh": "box", "transform": { "scale": 0.5, "anchor": "base", "translate": [3, 1, -2] } } ])"),
        kOrigin);
    Eigen::AlignedBox3d box;
    for (const auto& p : scene.meshes[1].positions) box.extend(scene.instances[0].object_to_world * p.cast<double>());
    EXPECT_NEAR(box.min().y(), 1.0, 1e-6);
    EXPECT_NEAR(box.center().x(), 3.0, 1e-6);
    EXPECT_NEAR(box.center().z(), -2.0, 1e-6);
    EXPECT_NEAR(box.max().y() - box.min().y(), 1.0, 1e-6);  // 2 m box at scale 0.5
}

TEST(SceneFile, FarFromOriginMeshesAreRecentredWithoutLosingPlacement) {
    // The transform moves the object 1e5 m away; the world position must survive in double.
    const Scene scene = parse_scene(
        minimal(R"([ { "mesh": "ball", "transform": { "translate": [100000.25, 0, -100000.5] } } ])"), kOrigin);
    const Eigen::Vector3d centre = scene.instances[0].object_to_world * Eigen::Vector3d::Zero();
    EXPECT_NEAR(centre.x(), 100000.25, 1e-9);
    EXPECT_NEAR(centre.z(), -100000.5, 1e-9);
}

TEST(SceneFile, RingMakesCopiesFacingTheAxis) {
    const Scene scene =
        parse_scene(minimal(R"([ { "mesh": "ball", "ring": { "count": 5, "radius": 4, "start_deg": -90, "end_deg": 90,)"
                            R"( "heights": [0, 2] } } ])"),
                    kOrigin);
    ASSERT_EQ(scene.instances.size(), 10u);
    for (const Instance& instance : scene.instances) {
        const Eigen::Vector3d c = instance.object_to_world.translation();
        EXPECT_NEAR(std::hypot(c.x(), c.z()), 4.0, 1e-9) << instance.name;
        // The copy's +z (its front) points at the axis.
        const Eigen::Vector3d front = instance.object_to_world.linear() * Eigen::Vector3d::UnitZ();
        EXPECT_NEAR(front.dot(-Eigen::Vector3d(c.x(), 0, c.z()).normalized()), 1.0, 1e-9) << instance.name;
    }
    EXPECT_NEAR(scene.instances[5].object_to_world.translation().y(), 2.0, 1e-12);
}

// Numerical stability: NaN and Infinity are not JSON; a number beyond double range
// (1e999) is refused by the JSON reader naming the file and the literal (it used to escape as a
// bare nlohmann out_of_range without the file); the largest finite doubles are refused naming the
// field and its limit in every kind of number the scene reads (root scalar, transform, material,
// light, procedural parameter, viewer).
TEST(SceneFile, NonFiniteAndHugeNumbersAreRefused) {
    const std::string ball = R"([ { "mesh": "ball" } ])";
    expect_error(minimal(ball, R"(, "exposure": NaN)"), {"not valid JSON"});
    expect_error(minimal(ball, R"(, "exposure": Infinity)"), {"not valid JSON"});
    expect_error(minimal(ball, R"(, "exposure": 1e999)"), {"out of range", "1e999"});
    expect_error(minimal(R"([ { "mesh": "ball", "transform": { "translate": [0, -1e999, 0] } } ])"),
                 {"out of range", "1e999"});
    expect_error(minimal(ball, R"(, "exposure": 1e308)"), {"exposure", "outside"});
    expect_error(minimal(R"([ { "mesh": "ball", "transform": { "rotate_deg": [0, -1e308, 0] } } ])"),
                 {"objects[0].transform.rotate_deg[1]"});
    expect_error(minimal(R"([ { "mesh": "ball", "transform": { "scale": 1e308 } } ])"), {"objects[0].transform.scale"});
    expect_error(
        R"({ "meshes": { "b": { "procedural": "uv_sphere", "radius": 1e308 } }, "objects": [ { "mesh": "b" } ] })",
        {"meshes.b", "radius"});
    expect_error(
        R"({ "meshes": { "b": { "procedural": "box", "size": [1, 1e308, 1] } }, "objects": [ { "mesh": "b" } ] })",
        {"meshes.b", "size"});
    expect_error(minimal(ball, R"(, "materials": { "m": { "albedo": [0.5, 1e308, 0.5] } })"), {"albedo"});
    expect_error(
        minimal(ball, R"(, "lights": [ { "type": "sun", "direction_to_light": [0, 1e308, 0], "irradiance": 1 } ])"),
        {"lights[0]"});
    expect_error(minimal(ball, R"(, "lights": [ { "type": "point", "position": [0, 1, 0], "intensity": 1e308 } ])"),
                 {"lights[0].intensity"});
    expect_error(minimal(ball, R"(, "viewer": { "start": [0, 1e308, 0] })"), {"viewer.start"});
    expect_error(minimal(ball, R"(, "viewer": { "start_yaw_deg": -1e308 })"), {"viewer.start_yaw_deg"});
}

TEST(SceneFile, RobustIntersectionFlagIsReadAndChecked) {
    EXPECT_FALSE(parse_scene(minimal(R"([ { "mesh": "ball" } ])"), kOrigin).robust_intersection);
    EXPECT_TRUE(parse_scene(minimal(R"([ { "mesh": "ball" } ])", R"(, "robust_intersection": true)"), kOrigin)
                    .robust_intersection);
    expect_error(minimal(R"([ { "mesh": "ball" } ])", R"(, "robust_intersection": 1)"),
                 {"robust_intersection", "true or false"});
}

TEST(SceneFile, BadInputNamesTheFieldAndTheRule) {
    expect_error("{ not json", {"not valid JSON"});
    expect_error(R"({ "objects": [] })", {"meshes", "missing"});
    expect_error(minimal("[]"), {"objects", "non-empty"});
    expect_error(minimal(R"([ { "mesh": "teapot" } ])"), {"objects[0].mesh", "teapot"});
    expect_error(minimal(R"([ { "mesh": "ball", "material": "gold" } ])"), {"objects[0].material", "gold"});
    expect_error(minimal(R"([ { "mesh": "ball", "transform": { "scale": 0 } } ])"),
                 {"objects[0].transform.scale", "outside"});
    expect_error(minimal(R"([ { "mesh": "ball", "transform": { "scale": -1 } } ])"), {"objects[0].transform.scale"});
    expect_error(minimal(R"([ { "mesh": "ball", "transform": { "translate": [0, 1e300, 0] } } ])"),
                 {"objects[0].transform.translate[1]", "outside"});
    expect_error(minimal(R"([ { "mesh": "ball", "transform": { "translate": [0, 0] } } ])"),
                 {"translate", "3 numbers"});
    expect_error(minimal(R"([ { "mesh": "ball", "transform": { "anchor": "top" } } ])"), {"anchor"});
    expect_error(minimal(R"([ { "mesh": "ball", "colour": 1 } ])"), {"objects[0].colour", "unknown key"});
    expect_error(minimal(R"([ { "mesh": "ball" } ])", R"(, "lights": [ { "type": "laser" } ])"),
                 {"lights[0].type", "laser"});
    expect_error(
        minimal(R"([ { "mesh": "ball" } ])", R"(, "lights": [ { "type": "sun", "direction_to_light": [0, 0, 0] } ])"),
        {"lights[0].direction_to_light", "zero"});
    expect_error(
        minimal(R"([ { "mesh": "ball" } ])",
                R"(, "lights": [ { "type": "area", "corner": [0,0,0], "edge_u": [1,0,0], "edge_v": [2,0,0] } ])"),
        {"lights[0]", "area"});
    expect_error(
        R"({ "meshes": { "room": { "procedural": "grotto_room", "radius": -3 } }, "objects": [ { "mesh": "room" } ] })",
        {"meshes.room", "radius"});
    expect_error(R"({ "meshes": { "m": { "procedural": "torus" } }, "objects": [ { "mesh": "m" } ] })",
                 {"meshes.m.procedural", "torus"});
    expect_error(R"({ "meshes": { "m": { "file": "missing.obj" } }, "objects": [ { "mesh": "m" } ] })",
                 {"meshes.m.file", "missing.obj", "does not exist"});
}

// lights[].animation: the light's power over scene time, piecewise constant, the list repeating.
TEST(SceneFile, AnimatedLightsScaleTheirPowerStepByStep) {
    const Scene scene = parse_scene(minimal(R"([ { "mesh": "ball" } ])", R"(, "lights": [
            { "type": "point", "position": [0, 2, 0], "animation": { "step_s": 0.5, "scale": [1, 0.25, 0] } },
            { "type": "sun", "direction_to_light": [0, 1, 0] } ])"),
                                    kOrigin);
    ASSERT_EQ(scene.point_lights.size(), 1u);
    ASSERT_EQ(scene.animated_lights.size(), 1u);
    EXPECT_EQ(scene.animated_lights[0].kind, LightKind::point);
    EXPECT_EQ(scene.animated_lights[0].index, 0u);
    const LightAnimation& a = scene.animated_lights[0].animation;
    EXPECT_FLOAT_EQ(a.scale_at(0.0), 1.f);
    EXPECT_FLOAT_EQ(a.scale_at(0.49), 1.f);
    EXPECT_FLOAT_EQ(a.scale_at(0.5), 0.25f);
    EXPECT_FLOAT_EQ(a.scale_at(1.2), 0.f);
    EXPECT_FLOAT_EQ(a.scale_at(1.5), 1.f);  // the list repeats
    EXPECT_FLOAT_EQ(a.scale_at(-3.0), 1.f);
    EXPECT_FLOAT_EQ(a.scale_at(std::nan("")), 1.f);
    EXPECT_FLOAT_EQ(light_scale(scene, LightKind::sun, 0, 1.2), 1.f);  // not animated
    EXPECT_FLOAT_EQ(light_scale(scene, LightKind::point, 0, 1.2), 0.f);
    // Only the animated light is in the state; equal states at times one period apart.
    EXPECT_EQ(lighting_state(scene, 0.1), std::vector<float>{1.f});
    EXPECT_EQ(lighting_state(scene, 0.6), std::vector<float>{0.25f});
    EXPECT_EQ(lighting_state(scene, 1.6), lighting_state(scene, 0.1));
    EXPECT_TRUE(lighting_state(parse_scene(minimal(R"([ { "mesh": "ball" } ])"), kOrigin), 3.0).empty());

    const auto with_animation = [](const std::string& animation) {
        return minimal(R"([ { "mesh": "ball" } ])",
                       R"(, "lights": [ { "type": "point", "position": [0, 2, 0], "animation": )" + animation + " } ]");
    };
    expect_error(with_animation("3"), {"lights[0].animation", "expected an object"});
    expect_error(with_animation(R"({ "scale": [1] })"), {"lights[0].animation.step_s", "missing"});
    expect_error(with_animation(R"({ "step_s": 0, "scale": [1] })"), {"lights[0].animation.step_s", "outside"});
    expect_error(with_animation(R"({ "step_s": 1, "scale": [] })"), {"lights[0].animation.scale", "1 to 4096"});
    expect_error(with_animation(R"({ "step_s": 1, "scale": [1, -2] })"), {"lights[0].animation.scale[1]", "outside"});
    expect_error(with_animation(R"({ "step_s": 1, "scale": [1], "ease": "in" })"),
                 {"lights[0].animation.ease", "unknown key"});
}

TEST(Procedural, GrottoRoomIsClosedExceptTheEntranceAndFacesInward) {
    GrottoRoomParams p;
    p.segments = 64;
    p.rings = 8;
    const Mesh room = make_grotto_room(p);
    ASSERT_GT(room.triangle_count(), 0u);
    // Every wall/dome triangle faces the axis: its normal points toward the centre line.
    int outward = 0;
    for (const auto& t : room.triangles) {
        const Eigen::Vector3f a = room.positions[t[0]], b = room.positions[t[1]], c = room.positions[t[2]];
        const Eigen::Vector3f n = (b - a).cross(c - a);
        const Eigen::Vector3f centroid = (a + b + c) / 3;
        if (centroid.y() < 1e-6f) {  // floor faces up
            outward += n.y() <= 0;
            continue;
        }
        // Wall and dome face the axis point at their height (at most the dome's springing line).
        const Eigen::Vector3f target(0, std::min(centroid.y(), static_cast<float>(p.height)), 0);
        outward += n.dot(target - centroid) <= 0;
    }
    EXPECT_EQ(outward, 0);
    EXPECT_THROW(make_grotto_room(GrottoRoomParams{.radius = 0.1}), std::invalid_argument);
}

TEST(SceneFile, GrottoScenesHaveTheRequiredTriangleCounts) {
    const std::filesystem::path scans = MOGAO_SCANS_DIR;
    if (!std::filesystem::exists(scans))
        GTEST_SKIP() << "real scans not found at " << scans << " (../shared/data/scans)";
    const std::filesystem::path scenes = std::filesystem::path(MOGAO_SOURCE_DIR) / "scenes";
    SceneLoadReport report;
    const Scene grotto = load_scene(scenes / "grotto.json", {scans}, &report);
    EXPECT_GE(grotto.triangle_count(), 500'000u);
    EXPECT_EQ(report.instanced_triangles, grotto.triangle_count());
    for (const MeshLoadFigures& m : report.meshes) {
        EXPECT_GT(m.triangles, 0u) << m.name;
        std::printf("%-10s %9zu triangles %8zu vertices %7.3f s  %s\n", m.name.c_str(), m.triangles, m.vertices,
                    m.seconds, m.source.c_str());
    }
    const Scene big = load_scene(scenes / "grotto-6m.json", {scans});
    EXPECT_GE(big.triangle_count(), 6'000'000u);
    // Instancing: the 6M variant holds no more distinct meshes than it names.
    EXPECT_LE(big.meshes.size(), grotto.meshes.size() + 1);
}

}  // namespace
}  // namespace mogao
