// SPDX-License-Identifier: Apache-2.0
// Textures filtered by ray cones (texture_lod.h): a texture minified far below its resolution is
// rendered as the light its pixels cover (ground truth: the texture's mean on a fine checker), not
// as the one texel each camera ray happens to hit; a magnified texture is left untouched.
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>

#include <gtest/gtest.h>

#include "renderfarm/scene/texture.h"
#include "renderfarm/trace/camera.h"
#include "renderfarm/trace/renderer.h"
#include "renderfarm/trace/test_scenes.h"
#include "renderfarm/trace/texture_lod.h"

namespace mogao {
namespace {

// A one-texel checker of codes 0 and 255: linear mean exactly 0.5.
std::shared_ptr<Texture> checker(int texels, bool chain) {
    auto t = std::make_shared<Texture>();
    t->source = "test:checker";
    t->image = Rgb8Image({texels, texels});
    for (int y = 0; y < texels; ++y)
        for (int x = 0; x < texels; ++x)
            for (int c = 0; c < 3; ++c) t->image.at(x, y)[c] = (x + y) % 2 ? 255 : 0;
    if (chain) t->mips = make_mip_chain(t->image);
    return t;
}

// A 1 m square in the z = 0 plane facing +z, uv (0, 0) at its top-left, tilted by `tilt_deg` about x;
// textured with `texture`, or (null) tinted by the checker's mean through vertex colours.
Scene square(std::shared_ptr<const Texture> texture, double tilt_deg = 0.0) {
    Mesh m;
    m.positions = {{-0.5f, -0.5f, 0.0f}, {0.5f, -0.5f, 0.0f}, {0.5f, 0.5f, 0.0f}, {-0.5f, 0.5f, 0.0f}};
    m.triangles = {{0, 1, 2}, {0, 2, 3}};
    if (texture) {
        m.uvs = {{0.0f, 1.0f}, {1.0f, 1.0f}, {1.0f, 0.0f}, {0.0f, 0.0f}};
        m.texture = std::move(texture);
    } else {
        m.colors.assign(4, Eigen::Vector3f::Constant(0.5f));
    }
    Scene scene;
    scene.source = "test:square";
    scene.meshes.push_back(std::move(m));
    scene.materials = {Material{}};
    Instance inst{"square", 0, 0, Eigen::Affine3d::Identity()};
    inst.object_to_world.rotate(Eigen::AngleAxisd(tilt_deg * std::numbers::pi / 180.0, Eigen::Vector3d::UnitX()));
    scene.instances = {inst};
    DirectionalLight sun;
    sun.direction_to_light = Eigen::Vector3d(0.0, 0.3, 1.0).normalized();
    sun.cast_shadows = false;
    scene.directional_lights = {sun};
    return scene;
}

// 64x64, fov 40 deg, from 1.1 m: the view (0.8 m) inside the square, a pixel 1.25 cm.
RgbFloatImage render(const Scene& scene, int spp = 1) {
    Renderer renderer(scene, RendererOptions{"threads=1", true});
    ViewRequest request = test::look_at({0.0, 0.0, 1.1}, {0.0, 0.0, 0.0}, {64, 64}, 40.0);
    request.quality.spp = spp;
    renderer.begin_frame(request);
    RgbFloatImage frame(renderer.render_size());
    renderer.render(PixelRect::whole(frame.size), frame);
    return frame;
}

// PSNR (dB) of `image` against `truth`, peak = the truth's largest value.
double psnr(const RgbFloatImage& image, const RgbFloatImage& truth) {
    double se = 0.0, peak = 0.0;
    for (std::size_t i = 0; i < truth.pixels.size(); ++i) {
        EXPECT_TRUE(std::isfinite(image.pixels[i]));
        const double d = image.pixels[i] - truth.pixels[i];
        se += d * d;
        peak = std::max(peak, static_cast<double>(truth.pixels[i]));
    }
    return 10.0 * std::log10(peak * peak / (se / static_cast<double>(truth.pixels.size())));
}

TEST(TextureLod, RayConeFormula) {
    // A 1 m square carrying a 512² texture: 512 texels per metre (Δ0 = 9).
    const float texel_area = 512.0f * 512.0f, world_area = 1.0f;
    EXPECT_NEAR(texture_lod(0.0125f, 1.0f, texel_area, world_area), std::log2(6.4f), 1e-5f);
    EXPECT_NEAR(texture_lod(0.0125f, 0.5f, texel_area, world_area), std::log2(12.8f), 1e-5f);  // foreshortened
    EXPECT_EQ(texture_lod(0.0f, 1.0f, texel_area, world_area), 0.0f);
    EXPECT_EQ(texture_lod(0.01f, 1.0f, 0.0f, world_area), 0.0f);                   // degenerate uvs
    EXPECT_EQ(texture_lod(0.01f, 1.0f, texel_area, 0.0f), 0.0f);                   // degenerate triangle
    EXPECT_TRUE(std::isfinite(texture_lod(0.01f, 0.0f, texel_area, world_area)));  // grazing
}

TEST(TextureLod, CameraSpreadIsOnePixelsAngle) {
    ViewRequest request = test::look_at({0.0, 0.0, 1.0}, {0.0, 0.0, 0.0}, {100, 100}, 90.0);
    const CameraSetup pinhole = make_camera_setup(request, {100, 100});
    EXPECT_NEAR(camera_cone_spread(pinhole, 1), std::atan(0.02), 1e-12);
    EXPECT_NEAR(camera_cone_spread(pinhole, 4), 0.5 * std::atan(0.02), 1e-12);
    EXPECT_NEAR(camera_cone_spread(pinhole, 4096), 0.125 * std::atan(0.02), 1e-12);
    // Cylinder: radius 3 m, 180 deg over 942 columns (1 cm each), 2.5 m over 250 rows (1 cm), the
    // eye 1.6 m up on the axis: the centre point is sqrt(9 + 0.35²) m away.
    CylinderScreen screen;
    screen.arc_deg = 180.0;
    request.camera = screen;
    const CameraSetup cylinder = make_camera_setup(request, {942, 250});
    EXPECT_NEAR(camera_cone_spread(cylinder, 1), std::atan(0.01 / std::hypot(3.0, 0.35)), 1e-5);
}

TEST(RendererTextureLod, AMinifiedTextureRendersAsTheLightItsPixelsCover) {
    // 6.4 texels per pixel: at 1 spp (pixel centres) a level-0 lookup sees one texel, 0 or 1.
    const RgbFloatImage truth = render(square(nullptr));
    const double filtered = psnr(render(square(checker(512, true))), truth);
    const double unfiltered = psnr(render(square(checker(512, false))), truth);
    EXPECT_GT(filtered, 35.0);
    EXPECT_LT(unfiltered, 15.0);  // what the renderer did before, and does without a chain
    // Several samples per pixel: a narrower cone (1/4 of a pixel at 16 spp) and the samples' mean.
    const double spp16 = psnr(render(square(checker(512, true)), 16), truth);
    EXPECT_GT(spp16, 30.0);
    // Tilted 60 deg: foreshortened, still the mean (the isotropic filter takes the long side).
    const RgbFloatImage tilted_truth = render(square(nullptr, 60.0));
    const double tilted = psnr(render(square(checker(512, true), 60.0)), tilted_truth);
    EXPECT_GT(tilted, 30.0);
    std::printf(
        "PSNR against the mean: 1 spp filtered %.1f dB, unfiltered %.1f dB; 16 spp %.1f dB; tilted 60 deg %.1f dB\n",
        filtered, unfiltered, spp16, tilted);
}

TEST(RendererTextureLod, AMagnifiedTextureIsNotBlurred) {
    // 8x8 texels over the square: 0.1 texel per pixel, level of detail < 0: exactly the level-0
    // lookup, chain or not.
    const RgbFloatImage with_chain = render(square(checker(8, true)));
    const RgbFloatImage without = render(square(checker(8, false)));
    ASSERT_EQ(with_chain.pixels.size(), without.pixels.size());
    for (std::size_t i = 0; i < without.pixels.size(); ++i) ASSERT_EQ(with_chain.pixels[i], without.pixels[i]) << i;
}

}  // namespace
}  // namespace mogao
