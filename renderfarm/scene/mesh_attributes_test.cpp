// SPDX-License-Identifier: Apache-2.0
// Colours, texture coordinates, textures and precision far from the origin in load_mesh.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "renderfarm/scene/mesh_io.h"
#include "renderfarm/scene/texture.h"

namespace mogao {
namespace {

namespace fs = std::filesystem;

class MeshAttributes : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() /
               fmt::format("mogao-mesh-attr-{}", ::testing::UnitTest::GetInstance()->random_seed());
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    fs::path write(const std::string& name, const std::string& text) const {
        const fs::path p = dir_ / name;
        std::ofstream(p, std::ios::binary) << text;
        return p;
    }
    fs::path dir_;
};

double srgb_decode(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }

TEST_F(MeshAttributes, PlyVertexColoursAreDecodedFromSrgb) {
    const std::string ply =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
        "property uchar red\nproperty uchar green\nproperty uchar blue\nelement face 1\n"
        "property list uchar int vertex_indices\nend_header\n"
        "0 0 0 255 0 128\n1 0 0 10 20 30\n0 1 0 0 0 0\n3 0 1 2\n";
    const Mesh m = load_mesh(write("c.ply", ply));
    ASSERT_EQ(m.colors.size(), 3u);
    EXPECT_FLOAT_EQ(m.colors[0].x(), 1.0f);
    EXPECT_FLOAT_EQ(m.colors[0].y(), 0.0f);
    EXPECT_NEAR(m.colors[0].z(), srgb_decode(128.0 / 255.0), 1e-6);
    EXPECT_NEAR(m.colors[1].y(), srgb_decode(20.0 / 255.0), 1e-7);
    // A float colour outside [0, 1] is an error naming the vertex and the property.
    std::string bad = ply;
    bad.replace(bad.find("property uchar red\nproperty uchar green\nproperty uchar blue"),
                std::string("property uchar red\nproperty uchar green\nproperty uchar blue").size(),
                "property float red\nproperty float green\nproperty float blue");
    bad.replace(bad.find("255 0 128"), 9, "1.5 0 0.5");
    try {
        (void)load_mesh(write("bad.ply", bad));
        FAIL() << "no error";
    } catch (const MeshLoadError& e) {
        EXPECT_NE(std::string(e.what()).find("vertex 0: colour red = 1.5 is outside [0, 1]"), std::string::npos)
            << e.what();
    }
}

// A millimetre-scale zig-zag 1e6 m from the file's origin: float has 6 cm steps there, so the
// detail only survives if the reader subtracts the centre in double before narrowing.
std::string far_vertices(const char* prefix, double offset) {
    std::string out;
    for (int i = 0; i < 8; ++i) {
        out += fmt::format("{}{:.9f} {:.9f} {:.9f}\n", prefix, offset + 0.001 * i, offset + 0.0007 * (i % 2),
                           -offset + 0.0003 * i);
    }
    return out;
}

void expect_exact_far(const Mesh& m, double offset) {
    ASSERT_EQ(m.positions.size(), 8u);
    for (int i = 0; i < 8; ++i) {
        const Eigen::Vector3d p = m.positions[static_cast<std::size_t>(i)].cast<double>() + m.origin;
        EXPECT_NEAR(p.x(), offset + 0.001 * i, 1e-7) << i;
        EXPECT_NEAR(p.y(), offset + 0.0007 * (i % 2), 1e-7) << i;
        EXPECT_NEAR(p.z(), -offset + 0.0003 * i, 1e-7) << i;
    }
    Mesh copy = m;
    const Eigen::Vector3d centre = recentre_mesh(copy);
    EXPECT_NEAR(centre.x(), offset + 0.0035, 1e-7);
    EXPECT_EQ(copy.origin, Eigen::Vector3d::Zero());
}

TEST_F(MeshAttributes, PlyFarFromOriginKeepsMillimetres) {
    std::string ply =
        "ply\nformat ascii 1.0\nelement vertex 8\nproperty double x\nproperty double y\nproperty double z\n"
        "element face 6\nproperty list uchar int vertex_indices\nend_header\n";
    ply += far_vertices("", 1e6);
    for (int i = 0; i < 6; ++i) ply += fmt::format("3 {} {} {}\n", i, i + 1, i + 2);
    expect_exact_far(load_mesh(write("far.ply", ply)), 1e6);
}

TEST_F(MeshAttributes, ObjFarFromOriginKeepsMillimetres) {
    std::string obj = far_vertices("v ", 1e6);
    for (int i = 1; i <= 6; ++i) obj += fmt::format("f {} {} {}\n", i, i + 1, i + 2);
    expect_exact_far(load_mesh(write("far.obj", obj)), 1e6);
}

TEST(Texture, BilinearBetweenTexelCentresWithWrapModes) {
    Texture t;
    t.image = Rgb8Image({2, 2});
    const std::uint8_t codes[4] = {0, 255, 255, 0};  // red channel: black, white / white, black
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) t.image.at(i, j)[0] = codes[j * 2 + i];
    // Texel centres read the texel exactly; halfway between two centres averages linear light.
    EXPECT_FLOAT_EQ(t.sample({0.25f, 0.25f}).x(), 0.0f);
    EXPECT_FLOAT_EQ(t.sample({0.75f, 0.25f}).x(), 1.0f);
    EXPECT_FLOAT_EQ(t.sample({0.5f, 0.25f}).x(), 0.5f);
    EXPECT_FLOAT_EQ(t.sample({0.5f, 0.5f}).x(), 0.5f);
    // Repeat: u = 0 lies halfway between texel 1 (wrapped) and texel 0.
    EXPECT_FLOAT_EQ(t.sample({0.0f, 0.25f}).x(), 0.5f);
    EXPECT_FLOAT_EQ(t.sample({1.25f, 0.25f}).x(), 0.0f);
    t.wrap_u = TextureWrap::clamp;
    EXPECT_FLOAT_EQ(t.sample({0.0f, 0.25f}).x(), 0.0f);
    EXPECT_FLOAT_EQ(t.sample({-7.0f, 0.25f}).x(), 0.0f);
    EXPECT_FLOAT_EQ(t.sample({9.0f, 0.25f}).x(), 1.0f);
    EXPECT_TRUE(t.sample({std::nanf(""), 1e30f}).allFinite());
    EXPECT_NEAR(srgb8_to_linear_table()[128], srgb_decode(128.0 / 255.0), 1e-7);
}

// The real photogrammetry scan with a 4096² JPEG texture (../shared/data/scans/bali-mask).
TEST(MeshAttributesScan, BaliMaskCarriesItsPaintedTexture) {
    const fs::path file = fs::path(MOGAO_SCANS_DIR) / "bali-mask" / "mask-gltf-2.0_separated-valid.gltf";
    if (!fs::exists(file)) GTEST_SKIP() << "real scan not found at " << file << " (../shared/data/scans)";
    MeshLoadReport report;
    const Mesh m = load_mesh(file, &report);
    EXPECT_EQ(m.triangles.size(), 100000u);
    ASSERT_EQ(m.uvs.size(), m.positions.size());
    ASSERT_NE(m.texture, nullptr);
    EXPECT_EQ(m.texture->image.size.width, 4096);
    EXPECT_EQ(m.texture->image.size.height, 4096);
    EXPECT_EQ(m.texture->wrap_u, TextureWrap::clamp);  // the file's sampler: CLAMP_TO_EDGE
    // Real colour: the texture sampled at the vertices is neither constant nor grey.
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double saturation = 0.0;
    for (const Eigen::Vector2f& uv : m.uvs) {
        ASSERT_GE(uv.minCoeff(), 0.0f);
        ASSERT_LE(uv.maxCoeff(), 1.0f);
        const Eigen::Vector3f c = m.texture->sample(uv);
        sum += c.cast<double>();
        saturation += c.maxCoeff() - c.minCoeff();
    }
    const Eigen::Vector3d mean = sum / static_cast<double>(m.uvs.size());
    saturation /= static_cast<double>(m.uvs.size());
    std::printf("bali-mask: mean linear colour (%.3f, %.3f, %.3f), mean max-min %.3f, loaded in %.2f s\n", mean.x(),
                mean.y(), mean.z(), saturation, report.seconds);
    EXPECT_GT(saturation, 0.03);
    EXPECT_GT(mean.maxCoeff(), 0.02);
}

}  // namespace
}  // namespace mogao
