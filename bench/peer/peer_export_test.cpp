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
    std::ifstream in(dir / "peer.json");
    const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    for (const char* key : {"\"vertical_fov_deg\"", "\"point\"", "\"sun\"", "\"area\"", "\"environment\"", "\"gilt\""})
        EXPECT_NE(text.find(key), std::string::npos) << key;
    r.camera = CylinderScreen{};
    EXPECT_THROW((void)write_peer_json(scene, r, dir), std::invalid_argument);
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
