// SPDX-License-Identifier: Apache-2.0
// Numerical stability of the renderer at the extremes (docs/renderer.md, "Numerical
// stability"). Each test names the guard it checks; all are small renders (< 0.1 MPixel).
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <embree3/rtcore.h>
#include <gtest/gtest.h>

#include "renderfarm/scene/procedural.h"
#include "renderfarm/trace/camera.h"
#include "renderfarm/trace/render_scene.h"
#include "renderfarm/trace/renderer.h"
#include "renderfarm/trace/test_scenes.h"

namespace mogao {
namespace {

constexpr float kAlbedo = 0.5f;
constexpr float kSunE = 3.0f;
constexpr float kSky = 0.2f;

RgbFloatImage render(const Scene& scene, const ViewRequest& request) {
    Renderer renderer(scene, RendererOptions{"threads=1", true});
    renderer.begin_frame(request);
    RgbFloatImage frame(renderer.render_size());
    renderer.render(PixelRect::whole(frame.size), frame);
    return frame;
}

void expect_finite_non_negative(const RgbFloatImage& image, const std::string& what) {
    for (std::size_t i = 0; i < image.pixels.size(); ++i) {
        ASSERT_TRUE(std::isfinite(image.pixels[i]) && image.pixels[i] >= 0.0f)
            << what << ": value " << i << " = " << image.pixels[i];
    }
}

Material grey() {
    Material m;
    m.albedo = Rgb(kAlbedo, kAlbedo, kAlbedo);
    return m;
}

// World scaled by `scale` and moved by `offset`: a ground plane, a sphere and a 1 mm (x scale)
// thin roof over part of the floor, as meshes in "file units" of 1/unit_scale world units each
// placed by an instance with that scale (a mm-unit mesh has unit_scale 1e-3). Sun + sky only
// (both scale invariant), so every scaled / moved copy must give the same image.
Scene scaled_world(double scale, const Eigen::Vector3d& offset, double unit_scale) {
    Scene scene;
    const double file_units = scale / unit_scale;  // mesh coordinates per metre of the reference
    Mesh floor = test::make_grid(8, static_cast<float>(4.0 * file_units), false);
    Mesh sphere = make_uv_sphere(0.5 * file_units, 48, 24);
    Mesh roof = make_box(1.5 * file_units, 1e-3 * file_units, 1.5 * file_units);
    scene.meshes = {floor, sphere, roof};
    scene.materials = {grey()};
    const auto place = [&](std::size_t mesh, const Eigen::Vector3d& at) {
        Instance inst{"i" + std::to_string(mesh), mesh, 0, Eigen::Affine3d::Identity()};
        inst.object_to_world.translate(offset + scale * at);
        inst.object_to_world.scale(unit_scale);
        scene.instances.push_back(inst);
    };
    place(0, {0.0, 0.0, 0.0});
    place(1, {-1.0, 0.5, 0.0});
    place(2, {1.2, 0.6, 0.0});
    DirectionalLight sun;
    sun.direction_to_light = Eigen::Vector3d(-0.3, 1.0, 0.2).normalized();
    sun.irradiance = Rgb(kSunE, kSunE, kSunE);
    scene.directional_lights = {sun};
    scene.environment_lights = {EnvironmentLight{Rgb(kSky, kSky, kSky)}};
    return scene;
}

ViewRequest scaled_view(double scale, const Eigen::Vector3d& offset) {
    ViewRequest request = test::look_at(offset + scale * Eigen::Vector3d(0.0, 2.5, 4.0),
                                        offset + scale * Eigen::Vector3d(0.2, 0.3, 0.0), {64, 48}, 60.0);
    request.quality.ao_samples = 2;
    request.quality.max_bounces = 1;
    return request;
}

struct ImageDiff {
    double mean_rel = 0.0;          // mean |a - b| / mean(a)
    double outlier_fraction = 0.0;  // values differing by more than 5 % of mean(a)
};

ImageDiff compare(const RgbFloatImage& a, const RgbFloatImage& b) {
    double sum = 0.0;
    double level = 0.0;
    for (const float v : a.pixels) level += v;
    level /= static_cast<double>(a.pixels.size());
    std::size_t outliers = 0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) {
        const double d = std::abs(static_cast<double>(a.pixels[i]) - b.pixels[i]);
        sum += d;
        if (d > 0.05 * level) ++outliers;
    }
    const auto n = static_cast<double>(a.pixels.size());
    return {sum / n / level, static_cast<double>(outliers) / n};
}

// Guard: rebasing + scale-aware ray offsets. The same world at the origin, moved by 1e3 and 1e6 m
// (1e5 is RendererFarOrigin), scaled by 1e-3 (mm-sized) and 1e3 (km-sized), and built from
// mm- and km-unit meshes, renders the same image: mean |diff| <= 1e-3 of the mean (2e-3 for the
// 8 mm world, see below) and at most
// 0.5 % of the values off by > 5 % (a shadow/AO ray flipping at a silhouette).
TEST(RendererStability, TranslatedAndScaledWorldsRenderTheSameImage) {
    const RgbFloatImage reference =
        render(scaled_world(1.0, Eigen::Vector3d::Zero(), 1.0), scaled_view(1.0, Eigen::Vector3d::Zero()));
    expect_finite_non_negative(reference, "reference");
    struct Case {
        const char* name;
        double scale;
        Eigen::Vector3d offset;
        double unit_scale;
        double tolerance = 1e-3;  // mean |diff| / mean
    };
    const std::vector<Case> cases = {
        {"offset 1e3", 1.0, {1e3, 0.0, -1e3}, 1.0},
        {"offset 1e6", 1.0, {1e6, 2e5, -1e6}, 1.0},
        // A whole world 8 mm across: the offset of secondary rays near the eye is a fixed 1.5e-5 m
        // (ray_offset.h), 1.5 % of the sphere, so contact shadows shift slightly (measured 1.0e-3).
        {"world x 1e-3", 1e-3, {0.0, 0.0, 0.0}, 1e-3, 2e-3},
        {"world x 1e3", 1e3, {0.0, 0.0, 0.0}, 1.0},
        {"mm-unit meshes", 1.0, {0.0, 0.0, 0.0}, 1e-3},
        {"km-unit meshes", 1.0, {0.0, 0.0, 0.0}, 1e3},
        {"km world at 1e6", 1e3, {1e6, 0.0, 1e6}, 1e3},
    };
    for (const Case& c : cases) {
        const RgbFloatImage image =
            render(scaled_world(c.scale, c.offset, c.unit_scale), scaled_view(c.scale, c.offset));
        expect_finite_non_negative(image, c.name);
        const ImageDiff d = compare(reference, image);
        std::printf("%-16s mean |diff| / mean = %.3g, outliers %.3g\n", c.name, d.mean_rel, d.outlier_fraction);
        EXPECT_LE(d.mean_rel, c.tolerance) << c.name;
        EXPECT_LE(d.outlier_fraction, 5e-3) << c.name;
    }
}

// Guard: no self-intersection acne and no light leaking through thin geometry, at every offset
// and scale. A camera looks down at the floor under a roof 1 mm thick (x scale) lit by the sun
// only: every pixel is exactly 0 (a leak would show sunlight). A camera over an open plane under
// sun + sky: every pixel equals the analytic albedo (E cos(theta) / pi + L_sky) within 1e-4
// relative (acne on the shadow or sky rays would darken pixels).
TEST(RendererStability, NoAcneAndNoLeakThroughThinRoofAtAnyScale) {
    const Eigen::Vector3d to_sun = Eigen::Vector3d(0.0, 1.0, 0.0);
    for (const double scale : {1e-3, 1.0, 1e3}) {
        for (const Eigen::Vector3d& offset : {Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(1e6, 1e3, -1e6)}) {
            const std::string what = "scale " + std::to_string(scale) + " offset " + std::to_string(offset.x());
            Scene scene = scaled_world(scale, offset, 1.0);
            scene.environment_lights.clear();
            scene.directional_lights[0].direction_to_light = to_sun;
            ViewRequest under = test::look_at(offset + scale * Eigen::Vector3d(1.2, 0.4, 0.0),
                                              offset + scale * Eigen::Vector3d(1.2, 0.0, 0.0), {24, 24}, 60.0);
            // Direct light only: a bounce off the roof's underside could fetch (legitimate) light
            // from the sunlit floor beyond the roof.
            const RgbFloatImage dark = render(scene, under);
            float brightest = 0.0f;
            for (const float v : dark.pixels) brightest = std::max(brightest, v);
            EXPECT_EQ(brightest, 0.0f) << what << ": light leaks under the roof";

            Scene open = scaled_world(scale, offset, 1.0);
            open.instances.resize(1);  // the plane alone
            const RgbFloatImage lit =
                render(open, test::look_at(offset + scale * Eigen::Vector3d(0.0, 1.0, 1.0), offset, {24, 24}, 60.0));
            const double cos_sun = open.directional_lights[0].direction_to_light.y();
            const double expected = kAlbedo * (kSunE * cos_sun / 3.14159265358979 + kSky);
            for (std::size_t i = 0; i < lit.pixels.size(); ++i) {
                ASSERT_NEAR(lit.pixels[i], expected, 1e-4 * expected) << what << ": value " << i;
            }
        }
    }
}

// --- watertightness -----------------------------------------------------------------------------

// Icosphere: an icosahedron subdivided `levels` times, vertices pushed to the unit sphere; shared
// vertices (a closed 2-manifold).
Mesh make_icosphere(int levels) {
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    std::vector<Eigen::Vector3d> v = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                                      {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
    for (auto& p : v) p.normalize();
    std::vector<std::array<std::uint32_t, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                                   {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                                   {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                                   {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    for (int l = 0; l < levels; ++l) {
        std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
        const auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
            const auto key = std::minmax(a, b);
            const auto it = mid.find(key);
            if (it != mid.end()) return it->second;
            v.push_back((v[a] + v[b]).normalized());
            const auto index = static_cast<std::uint32_t>(v.size() - 1);
            mid.emplace(key, index);
            return index;
        };
        std::vector<std::array<std::uint32_t, 3>> next;
        for (const auto& tri : f) {
            const std::uint32_t a = midpoint(tri[0], tri[1]);
            const std::uint32_t b = midpoint(tri[1], tri[2]);
            const std::uint32_t c = midpoint(tri[2], tri[0]);
            next.insert(next.end(), {{tri[0], a, c}, {tri[1], b, a}, {tri[2], c, b}, {a, b, c}});
        }
        f = std::move(next);
    }
    Mesh mesh;
    mesh.source = "icosphere";
    for (const auto& p : v) mesh.positions.push_back(p.cast<float>());
    mesh.triangles = f;
    return mesh;
}

// Rays from `origins` (mesh frame) toward every vertex and toward points 1/2, 1/3 and 1/8 along
// every edge, traced through the renderer's own BVHs (RenderScene, rebased on `offset`). Returns
// the number that escape the closed mesh.
int count_escapes(const Mesh& mesh, double radius, const Eigen::Vector3d& offset, bool robust,
                  const std::vector<Eigen::Vector3d>& origins, int* traced) {
    Scene scene;
    scene.robust_intersection = robust;
    scene.meshes = {mesh};
    scene.materials = {grey()};
    Instance inst{"icosphere", 0, 0, Eigen::Affine3d::Identity()};
    inst.object_to_world.translate(offset);
    inst.object_to_world.scale(radius);
    scene.instances = {inst};
    RenderScene rs(scene, "threads=1");
    std::vector<Eigen::Vector3d> targets;
    for (const auto& p : mesh.positions) targets.push_back(p.cast<double>());
    for (const auto& tri : mesh.triangles) {
        for (int e = 0; e < 3; ++e) {
            const Eigen::Vector3d a = mesh.positions[tri[e]].cast<double>();
            const Eigen::Vector3d b = mesh.positions[tri[(e + 1) % 3]].cast<double>();
            for (const double s : {0.5, 1.0 / 3.0, 0.125}) targets.push_back(a + s * (b - a));
        }
    }
    int escapes = 0;
    *traced = 0;
    for (const Eigen::Vector3d& o : origins) {
        const Eigen::Vector3d eye = offset + radius * o;
        rs.rebase(eye);
        for (const Eigen::Vector3d& target : targets) {
            const Eigen::Vector3f dir = (radius * (target - o)).normalized().cast<float>();
            RTCRayHit rh{};
            rh.ray.org_x = rh.ray.org_y = rh.ray.org_z = 0.0f;
            rh.ray.dir_x = dir.x();
            rh.ray.dir_y = dir.y();
            rh.ray.dir_z = dir.z();
            rh.ray.tnear = 0.0f;
            rh.ray.tfar = std::numeric_limits<float>::infinity();
            rh.ray.mask = 0xFFFFFFFFu;
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
            RTCIntersectContext context;
            rtcInitIntersectContext(&context);
            rtcIntersect1(rs.root(), &context, &rh);
            ++*traced;
            if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) ++escapes;
        }
    }
    return escapes;
}

// Guard: watertight triangle intersection with Scene::robust_intersection. Rays aimed exactly at
// the vertices and edges of a closed icosphere (1280 triangles) from five interior points, at
// radius 1 mm, 1 m and 1 km, at the origin and 1e6 m away: with the flag (RTC_SCENE_FLAG_ROBUST)
// not one escapes. Without it (the default, for speed) Embree's faster triangle test lets some
// through (measured with Debian's Embree 3.13: 2.5-4.7 % of these adversarial rays); the count is
// printed, not asserted, since it depends on Embree's version.
TEST(RendererStability, RaysAimedAtSharedEdgesAndVerticesNeverEscapeAClosedMesh) {
    const Mesh sphere = make_icosphere(3);
    const std::vector<Eigen::Vector3d> origins = {
        {0.0, 0.0, 0.0}, {0.3, -0.2, 0.1}, {-0.5, 0.4, 0.2}, {0.0, 0.0, 0.9}, {0.61, 0.0, -0.61}};
    int total = 0;
    for (const double radius : {1e-3, 1.0, 1e3}) {
        for (const Eigen::Vector3d& offset : {Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(1e6, -1e5, 1e6)}) {
            int traced = 0;
            const int fast_escapes = count_escapes(sphere, radius, offset, false, origins, &traced);
            std::printf("radius %g offset %g: %d of %d rays escape without robust_intersection\n", radius, offset.x(),
                        fast_escapes, traced);
            const int escapes = count_escapes(sphere, radius, offset, true, origins, &traced);
            EXPECT_EQ(escapes, 0) << "radius " << radius << " offset " << offset.transpose() << ": " << escapes
                                  << " of " << traced << " rays escaped";
            total += traced;
        }
    }
    std::printf("watertightness: %d rays at edges/vertices with robust_intersection, 0 escapes allowed\n", total);
}

// --- degenerate geometry and non-finite input ---------------------------------------------------

// Guard: zero-area triangles (three equal vertices, collinear vertices), duplicated vertices and
// grazing views render finite, non-negative pixels no brighter than the analytic value of the
// lit plane (a NaN from normalising a zero normal would fail here).
TEST(RendererStability, DegenerateTrianglesDuplicateVerticesAndGrazingRaysStayFinite) {
    Scene scene = scaled_world(1.0, Eigen::Vector3d::Zero(), 1.0);
    scene.instances.resize(1);
    Mesh junk;
    junk.source = "degenerate";
    junk.positions = {{0.f, 0.5f, 0.f}, {0.f, 0.5f, 0.f},  {0.f, 0.5f, 0.f},  {-1.f, 0.2f, 0.f}, {0.f, 0.2f, 0.f},
                      {1.f, 0.2f, 0.f}, {0.f, 0.3f, -1.f}, {1.f, 0.3f, -1.f}, {0.f, 1.3f, -1.f}, {0.f, 0.3f, -1.f}};
    junk.normals = {{0.f, 0.f, 0.f}, {0.f, 1.f, 0.f}, {0.f, 1.f, 0.f}, {0.f, 1.f, 0.f}, {0.f, 1.f, 0.f},
                    {0.f, 1.f, 0.f}, {0.f, 0.f, 1.f}, {0.f, 0.f, 1.f}, {0.f, 0.f, 1.f}, {0.f, 0.f, 1.f}};
    // point triangle, collinear triangle, a real triangle and its copy on a duplicated vertex
    junk.triangles = {{0, 1, 2}, {3, 4, 5}, {6, 7, 8}, {9, 7, 8}};
    scene.meshes.push_back(junk);
    scene.instances.push_back(Instance{"junk", scene.meshes.size() - 1, 0, Eigen::Affine3d::Identity()});
    // Energy bound: direct light at normal incidence, times 1 / (1 - albedo) for all bounces.
    const double bound = kAlbedo * (kSunE / 3.14159265358979 + kSky) / (1.0 - kAlbedo) * 1.01;
    for (const double height : {1.0, 1e-3, 1e-6}) {  // down to a camera 1 um above the plane
        ViewRequest request = test::look_at({0.0, height, 3.0}, {0.0, height, 0.0}, {48, 32}, 60.0);
        request.quality.spp = 2;
        request.quality.ao_samples = 2;
        request.quality.max_bounces = 2;
        const RgbFloatImage image = render(scene, request);
        expect_finite_non_negative(image, "height " + std::to_string(height));
        for (const float v : image.pixels) ASSERT_LE(v, bound) << "height " << height;
    }
}

// Guard: non-finite vertices of a mesh built in code (scene files are checked by
// validate_mesh, mesh_io_test) are refused by the Renderer with an error naming the mesh and vertex.
TEST(RendererStability, NonFiniteVertexIsRefusedNamingTheMesh) {
    for (const float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
        Scene scene = scaled_world(1.0, Eigen::Vector3d::Zero(), 1.0);
        scene.meshes[1].positions[17].y() = bad;
        try {
            Renderer renderer(scene, RendererOptions{"threads=1", true});
            FAIL() << "accepted a non-finite vertex";
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find("mesh 1 vertex 17"), std::string::npos) << e.what();
        }
    }
}

// --- cameras at the extremes --------------------------------------------------------------------

// Guard: the cylindrical camera's ray maths (camera.h) at arcs from 1 to 360 degrees, the eye on
// the screen axis, off-axis inside and outside the cylinder, for a 1x1 frame and every column of
// three rows of an 8K (7680x4320) frame (checked directly, not rendered): every direction is
// finite and unit, passes through its pixel's screen point (angle < 1e-9 rad), and neighbouring
// columns are arc/W apart on the screen.
TEST(RendererStability, CylinderCameraRaysAtExtremeArcsEyesAndSizes) {
    const double kPi = 3.14159265358979323846;
    const std::vector<Eigen::Vector3d> eyes = {{0.0, 1.25, 0.0}, {0.5, 0.3, 1.0}, {0.0, 1.6, 10.0}, {-7.0, 4.0, -7.0}};
    long checked = 0;
    for (const double arc : {1.0, 90.0, 359.0, 360.0}) {
        for (const Eigen::Vector3d& eye : eyes) {
            for (const ImageSize size : {ImageSize{1, 1}, ImageSize{7680, 4320}}) {
                ViewRequest request;
                request.size = size;
                request.pose.yaw_deg = 37.0;
                request.pose.pitch_deg = -12.0;
                const CylinderScreen screen{3.0, arc, 0.0, 2.5, eye};
                request.camera = screen;
                const CameraSetup camera = make_camera_setup(request, size);
                for (const int row : {0, size.height / 2, size.height - 1}) {
                    for (int col = 0; col < size.width; ++col) {
                        const double px = col + 0.5;
                        const double py = row + 0.5;
                        const Ray ray = generate_ray(camera, px, py);
                        const double theta = (-arc / 2.0 + arc * px / size.width) * kPi / 180.0;
                        const double y = screen.top_m - (screen.top_m - screen.bottom_m) * py / size.height;
                        const Eigen::Vector3d on_screen(3.0 * std::sin(theta), y, -3.0 * std::cos(theta));
                        const Eigen::Vector3d expected = camera.rotation * (on_screen - eye).normalized();
                        ASSERT_TRUE(ray.direction.allFinite()) << "arc " << arc << " col " << col;
                        ASSERT_NEAR(ray.direction.norm(), 1.0, 1e-12) << "arc " << arc << " col " << col;
                        ASSERT_LT((ray.direction - expected).norm(), 1e-9) << "arc " << arc << " col " << col;
                        ++checked;
                    }
                }
            }
        }
    }
    std::printf("cylinder camera: %ld rays checked\n", checked);
}

// Guard: renders at the extremes give finite pixels: a 1x1 frame (pinhole and cylinder), a
// 7680x4 cylinder frame (8K wide) at 1 and 360 degrees, pinhole fields of view of 1e-6 and
// 179.9999 degrees, and the physical eye exactly on the screen (the pixel's ray direction is then
// undefined: the pixel must still be finite).
TEST(RendererStability, ExtremeCamerasRenderFinitePixels) {
    Scene scene = scaled_world(1.0, Eigen::Vector3d::Zero(), 1.0);
    Renderer renderer(scene, RendererOptions{"threads=1", true});
    const auto check = [&](const ViewRequest& request, PixelRect rect, const std::string& what) {
        renderer.begin_frame(request);
        RgbFloatImage frame(renderer.render_size());
        if (rect.x1 == 0) rect = PixelRect::whole(frame.size);
        renderer.render(rect, frame);
        expect_finite_non_negative(frame, what);
    };
    ViewRequest one = test::look_at({0.0, 1.0, 3.0}, {0.0, 0.5, 0.0}, {1, 1}, 60.0);
    check(one, {}, "pinhole 1x1");
    for (const double fov : {1e-6, 179.9999}) {
        ViewRequest r = test::look_at({0.0, 1.0, 3.0}, {0.0, 0.5, 0.0}, {16, 16}, fov);
        check(r, {}, "pinhole fov " + std::to_string(fov));
    }
    ViewRequest cyl;
    cyl.pose.eye = {0.0, 0.0, 2.0};
    cyl.size = {1, 1};
    cyl.camera = CylinderScreen{3.0, 180.0, 0.0, 2.5, {0.0, 1.6, 0.0}};
    check(cyl, {}, "cylinder 1x1");
    cyl.camera = CylinderScreen{3.0, 180.0, 0.0, 2.5, {0.0, 1.25, -3.0}};  // eye on the pixel's screen point
    check(cyl, {}, "eye on the screen");
    for (const double arc : {1.0, 360.0}) {
        cyl.size = {7680, 4};  // the full 8K width; 4 rows spanning the screen's height
        cyl.camera = CylinderScreen{3.0, arc, 0.0, 2.5, {0.0, 1.6, 0.0}};
        check(cyl, {}, "8K strip, arc " + std::to_string(arc));
    }
}

}  // namespace
}  // namespace mogao
