// SPDX-License-Identifier: Apache-2.0
#include "kiosk/display/frame_indirect_light.h"

#include <algorithm>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "appliance/autocal/model_store.h"
#include "appliance/warp/ideal_calibration.h"
#include "common/srgb.h"

namespace mogao {
namespace {

// One projector on the screen's axis facing the middle of the arc (device frame: x right, y down, z forward), its
// image over the ideal calibration's single projector: the patches it lights are what the field sees.
autocal::CalibrationModels facing_middle(double reflectance) {
    autocal::CalibrationModels m;
    m.screen.interreflection = reflectance;
    autocal::DeviceModel d;
    d.id = "proj0";
    d.resolution = {1024, 768};
    d.fx_px = d.fy_px = 700.0;
    d.cx_px = 512.0;
    d.cy_px = 384.0;
    d.rotation = Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();  // forward = -z, the arc's middle
    d.position_m = {0.0, 1.55, 0.0};
    m.projectors.push_back(d);
    m.camera = d;
    m.camera.id = "camera";
    return m;
}

ScreenCalibration one_projector() {
    IdealCalibrationParams p;
    p.projectors = 1;
    p.overlap = 0.0;
    p.content = {192, 108};
    return make_ideal_calibration(p);
}

// The frame's pixels decoded as the outputs decode them.
RgbFloatImage linear_of(const Rgb8Image& frame) {
    RgbFloatImage out(frame.size);
    for (std::size_t i = 0; i < frame.pixels.size(); ++i) out.pixels[i] = srgb8_decode_table()[frame.pixels[i]];
    return out;
}

// The field follows the frame where the outputs fetch it: a frame white on its left half and black on its right
// gives the model's field of those patch means; fetched through a late warp that shows only its left half, the
// field of an all-white frame.
TEST(FrameIndirectLight, TheFieldIsTheModelsForThePixelsTheOutputsFetch) {
    const ScreenCalibration screen = one_projector();
    const autocal::CalibrationModels m = facing_middle(0.8);
    const FrameIndirectLight light(autocal::IndirectLight(m.screen, m.projectors, screen));
    ASSERT_TRUE(light.model().active());
    Rgb8Image half(ImageSize{192, 108});
    for (int y = 0; y < 108; ++y)
        for (int x = 0; x < 96; ++x) std::fill_n(half.at(x, y), 3, std::uint8_t{255});
    const RgbFloatImage field = light.field(half, {});
    const RgbFloatImage expected = light.model().field(light.model().patch_means(linear_of(half)));
    ASSERT_EQ(field.pixels.size(), expected.pixels.size());
    for (std::size_t i = 0; i < field.pixels.size(); ++i) EXPECT_FLOAT_EQ(field.pixels[i], expected.pixels[i]) << i;
    EXPECT_GT(*std::max_element(field.pixels.begin(), field.pixels.end()), 0.01F);

    ContentTransform left_half;
    left_half.scale_u = 0.5F;
    const RgbFloatImage stretched = light.field(half, left_half);
    const RgbFloatImage white = light.model().flat_field(1.0);
    ASSERT_EQ(stretched.pixels.size(), white.pixels.size());
    for (std::size_t i = 0; i < white.pixels.size(); ++i) EXPECT_NEAR(stretched.pixels[i], white.pixels[i], 1e-6) << i;
    EXPECT_TRUE(light.field(Rgb8Image{}, {}).pixels.empty());
}

// Nothing to take off, said with the reason: no models file, or a screen that barely lights itself.
TEST(FrameIndirectLight, LoadsOnlyWhatHasSomethingToTakeOff) {
    const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "frame_indirect_light";
    std::filesystem::create_directories(dir);
    const ScreenCalibration screen = one_projector();
    std::string note;
    EXPECT_FALSE(load_frame_indirect_light(dir / "absent.models.json", screen, &note));
    EXPECT_NE(note.find("absent.models.json"), std::string::npos) << note;
    autocal::write_models(dir / "matte.models.json", facing_middle(0.004));
    EXPECT_FALSE(load_frame_indirect_light(dir / "matte.models.json", screen, &note));
    EXPECT_NE(note.find("below"), std::string::npos) << note;
    autocal::write_models(dir / "lit.models.json", facing_middle(0.8));
    EXPECT_TRUE(load_frame_indirect_light(dir / "lit.models.json", screen, &note)) << note;
    ScreenCalibration two = screen;
    two.projectors.push_back(two.projectors.front());
    EXPECT_FALSE(load_frame_indirect_light(dir / "lit.models.json", two, &note));
    EXPECT_NE(note.find("projector models"), std::string::npos) << note;
}

}  // namespace
}  // namespace mogao
