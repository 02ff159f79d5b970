// SPDX-License-Identifier: Apache-2.0
// The peer export (peer_export.h) writes the scene as loaded: the test room's OBJ reads back with the
// scene's triangle count, vertex count and world bounds (ring instancing and transforms applied);
// peer.json carries the camera and every light; a cylinder camera is refused; PFM round-trips with the
// bottom-up row order. No Blender needed.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

#include "bench/peer/peer_export.h"
#include "bench/peer/pfm_io.h"
#include "renderfarm/scene/scene_file.h"

namespace mogao::peer {
namespace {

std::filesystem::path temp_dir(const std::string& name) {
    const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / ("mogao_peer_" + name);
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

std::string file_text(const std::filesystem::path& file) {
    std::ifstream in(file);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// World bounds and vertex count straight from the loaded scene, independently of the writer.
ExportStats scene_stats(const Scene& scene) {
    ExportStats s;
    for (const Instance& inst : scene.instances) {
        const Mesh& mesh = scene.meshes[inst.mesh];
        for (const Eigen::Vector3f& p : mesh.positions) {
            const Eigen::Vector3d w = inst.object_to_world * (mesh.origin + p.cast<double>());
            s.lo = s.lo.cwiseMin(w);
            s.hi = s.hi.cwiseMax(w);
        }
        s.vertices += mesh.positions.size();
        s.triangles += mesh.triangles.size();
    }
    return s;
}

TEST(PeerExport, TestRoomRoundTripsTrianglesAndBounds) {
    const Scene scene = load_scene(std::filesystem::path(MOGAO_SOURCE_DIR) / "scenes" / "test-room.json");
    const std::filesystem::path dir = temp_dir("room");
    const Result<ExportStats> written = write_obj(scene, dir);
    ASSERT_TRUE(written.ok()) << written.error().message;
    const Result<ExportStats> read = read_obj_stats(dir / "scene.obj");
    ASSERT_TRUE(read.ok()) << read.error().message;
    const ExportStats expected = scene_stats(scene);
    EXPECT_EQ(read->triangles, scene.triangle_count());
    EXPECT_EQ(read->triangles, written->triangles);
    EXPECT_EQ(read->vertices, expected.vertices);
    // 9 significant digits in the file: bounds within 1e-6 m at the room's 5 m scale.
    EXPECT_LT((read->lo - expected.lo).cwiseAbs().maxCoeff(), 1e-6);
    EXPECT_LT((read->hi - expected.hi).cwiseAbs().maxCoeff(), 1e-6);
    // Six ring boxes around a 3 m radius: the export is not the single unplaced box mesh.
    EXPECT_GT(scene.instances.size(), 3u);
}

TEST(PeerExport, JsonHasCameraAndEveryLightAndRefusesCylinder) {
    const Scene scene = load_scene(std::filesystem::path(MOGAO_SOURCE_DIR) / "scenes" / "test-room.json");
    const std::filesystem::path dir = temp_dir("json");
    ViewRequest r;
    r.camera = PinholeCamera{45.0};
    r.size = {64, 48};
    ASSERT_TRUE(write_peer_json(scene, r, dir).ok());
    const std::string text = file_text(dir / "peer.json");
    for (const char* key : {"\"vertical_fov_deg\"", "\"point\"", "\"sun\"", "\"area\"", "\"environment\"", "\"gilt\""})
        EXPECT_NE(text.find(key), std::string::npos) << key;
    r.camera = CylinderScreen{};
    EXPECT_THROW((void)write_peer_json(scene, r, dir), std::invalid_argument);
}

// One textured triangle (a 2x1 texture, uvs in our top-left convention) and one plain instance: the
// textured one gets its own material with map_Kd, its vt lines with v flipped, v/vt/vn faces and the PNG.
TEST(PeerExport, TexturedMeshWritesItsCoordinatesTextureAndMaterial) {
    Scene scene;
    scene.source = "in-code";
    Mesh tri;
    tri.source = "tri";
    tri.positions = {{0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}};
    tri.normals = {{0.f, 0.f, 1.f}, {0.f, 0.f, 1.f}, {0.f, 0.f, 1.f}};
    tri.triangles = {{0u, 1u, 2u}};
    Mesh plain = tri;
    plain.source = "plain";
    tri.uvs = {{0.f, 0.f}, {1.f, 0.f}, {0.f, 0.25f}};
    auto texture = std::make_shared<Texture>();
    texture->source = "checker.png";
    texture->image = Rgb8Image(ImageSize{2, 1});
    texture->image.pixels = {255, 0, 0, 0, 0, 255};
    texture->wrap_v = TextureWrap::clamp;
    tri.texture = texture;
    scene.meshes = {tri, plain};
    scene.materials = {Material{"stone"}};
    scene.instances = {Instance{"a", 0, 0}, Instance{"b", 1, 0}};
    const std::filesystem::path dir = temp_dir("textured");
    const Result<ExportStats> written = write_obj(scene, dir);
    ASSERT_TRUE(written.ok()) << written.error().message;
    EXPECT_EQ(written->uvs, 3u);
    EXPECT_TRUE(std::filesystem::exists(dir / "texture0.png"));
    EXPECT_FALSE(std::filesystem::exists(dir / "texture1.png"));
    const Result<ExportStats> read = read_obj_stats(dir / "scene.obj");
    ASSERT_TRUE(read.ok()) << read.error().message;
    EXPECT_EQ(read->uvs, 3u);
    EXPECT_EQ(read->triangles, 2u);
    const std::string text = file_text(dir / "scene.obj");
    EXPECT_NE(text.find("usemtl stone__texture0\n"), std::string::npos) << text;
    EXPECT_NE(text.find("vt 0 0.75\n"), std::string::npos) << text;  // v = 0.25 down the image = 0.75 up it
    EXPECT_NE(text.find("f 1/1/1 2/2/2 3/3/3\n"), std::string::npos) << text;
    EXPECT_NE(text.find("f 4//4 5//5 6//6\n"), std::string::npos) << text;  // the plain instance
    const std::string mtl_text = file_text(dir / "scene.mtl");
    EXPECT_NE(mtl_text.find("newmtl stone__texture0\n"), std::string::npos) << mtl_text;
    EXPECT_NE(mtl_text.find("map_Kd texture0.png\n"), std::string::npos) << mtl_text;
    ViewRequest r;
    r.camera = PinholeCamera{45.0};
    r.size = {64, 48};
    ASSERT_TRUE(write_peer_json(scene, r, dir).ok());
    const std::string json_text = file_text(dir / "peer.json");
    EXPECT_NE(json_text.find("\"texture\": \"texture0.png\""), std::string::npos) << json_text;
    EXPECT_NE(json_text.find("\"clamp\""), std::string::npos) << json_text;
}

TEST(PeerExport, PfmRoundTripsAndRefusesTruncated) {
    RgbFloatImage img(ImageSize{3, 2});
    for (std::size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = 0.25f * static_cast<float>(i);
    const std::filesystem::path file = temp_dir("pfm") / "a.pfm";
    ASSERT_TRUE(write_pfm(file, img).ok());
    const Result<RgbFloatImage> back = read_pfm(file);
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back->pixels, img.pixels);
    // The first floats in the file are the BOTTOM row (PFM order).
    std::ifstream raw(file, std::ios::binary);
    std::string header;
    for (int lines = 0; lines < 3; ++lines) std::getline(raw, header);
    float first = 0.f;
    raw.read(reinterpret_cast<char*>(&first), sizeof first);
    EXPECT_EQ(first, *img.at(0, 1));
    std::filesystem::resize_file(file, std::filesystem::file_size(file) - 4);
    EXPECT_FALSE(read_pfm(file).ok());
}

}  // namespace
}  // namespace mogao::peer
