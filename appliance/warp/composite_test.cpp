// SPDX-License-Identifier: Apache-2.0
// The composite check of docs/calibration.md: render the ideal calibration's outputs from a
// content image, put them back on the screen, and compare with the content.
#include "appliance/warp/composite.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "appliance/warp/composite_check.h"
#include "appliance/warp/ideal_calibration.h"
#include "appliance/warp/response_curve.h"
#include "appliance/warp/warp_sampling.h"

namespace mogao {
namespace {

constexpr double kTolerance = 1.0 / 255.0;  // linear light, see docs/calibration.md

// Gradient + a smooth (sinusoidal) checker, values in [0.05, 0.95] (inside the response's [0, 1]). Smooth because the
// round trip resamples twice (content -> projector pixels -> content pixels); a hard-edged checker is blurred by one
// pixel there by design, which is interpolation, not calibration error.
RgbFloatImage test_content(ImageSize size) {
    RgbFloatImage img(size);
    const double period = 96.0;  // content pixels per checker cell pair
    for (int y = 0; y < size.height; ++y) {
        for (int x = 0; x < size.width; ++x) {
            const double gx = (x + 0.5) / size.width;
            const double gy = (y + 0.5) / size.height;
            const double checker = std::sin(2.0 * std::numbers::pi * (x + 0.5) / period) *
                                   std::sin(2.0 * std::numbers::pi * (y + 0.5) / period);
            float* p = img.at(x, y);
            p[0] = static_cast<float>(0.2 + 0.6 * gx + 0.15 * checker);
            p[1] = static_cast<float>(0.2 + 0.6 * gy + 0.15 * checker);
            p[2] = static_cast<float>(0.5 - 0.3 * gx * gy + 0.15 * checker);
        }
    }
    return img;
}

std::vector<RgbFloatImage> render_all(const ScreenCalibration& s, const RgbFloatImage& content) {
    std::vector<RgbFloatImage> outputs;
    for (const auto& p : s.projectors) outputs.push_back(render_output(p, content));
    return outputs;
}

// Content columns just right of each overlap edge (u0 of projector k+1 and u1 of projector k).
std::vector<int> overlap_edge_columns(const ScreenCalibration& s) {
    const auto bands = ideal_bands(static_cast<int>(s.projectors.size()), 0.15);
    std::vector<int> columns;
    for (std::size_t k = 0; k + 1 < bands.size(); ++k) {
        for (const double u : {bands[k + 1].u0, bands[k].u1}) {
            columns.push_back(static_cast<int>(std::lround(u * s.content.width)));
        }
    }
    return columns;
}

// Inner region: the frame minus 2 pixels, the outer half output pixel that the inverse leaves
// uncovered plus rounding (the CoverageIsTheFrameMinusItsBorder test bounds this).
PixelRect inner(ImageSize s) { return {2, 2, s.width - 2, s.height - 2}; }

TEST(Composite, SampleContentUsesPixelCentresAndClamps) {
    RgbFloatImage img({2, 1});
    img.pixels = {0.0F, 0.2F, 1.0F, 1.0F, 0.4F, 0.0F};
    EXPECT_EQ(sample_content(img, 0.25, 0.5)[1], 0.2F);  // pixel 0's centre
    EXPECT_EQ(sample_content(img, 0.75, 0.5)[0], 1.0F);  // pixel 1's centre
    EXPECT_FLOAT_EQ(sample_content(img, 0.5, 0.5)[1], 0.3F);
    EXPECT_FLOAT_EQ(sample_content(img, 0.375, 0.1)[2], 0.75F);
    EXPECT_EQ(sample_content(img, -5.0, 9.0)[2], 1.0F);  // clamp to pixel 0
    EXPECT_EQ(sample_content(img, NAN, 0.5)[0], 0.0F);
}

TEST(Composite, RenderOutputAppliesWarpBlendAndResponse) {
    IdealCalibrationParams p;
    p.projectors = 1;
    p.output = {8, 4};
    p.content = {8, 4};
    ScreenCalibration s = make_ideal_calibration(p);
    const RgbFloatImage content = test_content(p.content);
    s.projectors[0].blend.weight[5] = 0.5F;
    s.projectors[0].warp.uv[2 * 6] = NAN;
    s.projectors[0].warp.uv[2 * 6 + 1] = NAN;
    const RgbFloatImage out = render_output(s.projectors[0], content);
    for (int i = 0; i < 32; ++i) {
        for (int c = 0; c < 3; ++c) {
            const double linear = content.pixels[static_cast<std::size_t>(i * 3 + c)] * (i == 5 ? 0.5 : 1.0);
            const double expected = i == 6 ? 0.0 : std::pow(linear, 1.0 / 2.2);
            EXPECT_NEAR(out.pixels[static_cast<std::size_t>(i * 3 + c)], expected, 2e-5) << i;
        }
    }
}

TEST(Composite, IdealThreeProjectorsReproduceTheContent) {
    const ScreenCalibration s = make_ideal_calibration(IdealCalibrationParams{});  // 3 x 1024x768 -> 1920x1080
    const RgbFloatImage content = test_content(s.content);
    const RgbFloatImage screen = composite_on_screen(s, render_all(s, content));
    const ImageDifference d = compare_images(screen, content, inner(s.content));
    RecordProperty("max_abs_error", std::to_string(d.max_abs));
    RecordProperty("mean_abs_error", std::to_string(d.mean_abs));
    std::printf("composite vs content (inner): max %.3g at (%d, %d), mean %.3g\n", d.max_abs, d.max_x, d.max_y,
                d.mean_abs);
    EXPECT_LT(d.max_abs, kTolerance) << "at (" << d.max_x << ", " << d.max_y << ")";
    for (const int column : overlap_edge_columns(s)) {
        const double step = seam_step(screen, content, column, 2, s.content.height - 2);
        EXPECT_LT(step, kTolerance / 4) << "seam at column " << column;
    }
}

TEST(Composite, UniformContentHasNoSeam) {
    const ScreenCalibration s = make_ideal_calibration(IdealCalibrationParams{});
    const RgbFloatImage content(s.content, 0.5F);
    const RgbFloatImage screen = composite_on_screen(s, render_all(s, content));
    const ImageDifference d = compare_images(screen, content, inner(s.content));
    std::printf("uniform 0.5: max error %.3g\n", d.max_abs);
    EXPECT_LT(d.max_abs, 1e-4);
    for (const int column : overlap_edge_columns(s)) {
        for (int c = column - 2; c <= column + 2; ++c) {
            EXPECT_LT(seam_step(screen, content, c, 2, s.content.height - 2), 1e-4) << "column " << c;
        }
    }
}

TEST(Composite, CoverageIsTheFrameMinusItsBorder) {
    const ScreenCalibration s = make_ideal_calibration(IdealCalibrationParams{});
    const RgbFloatImage white(s.content, 1.0F);
    const RgbFloatImage screen = composite_on_screen(s, render_all(s, white));
    int uncovered_inside = 0;
    for (int y = 1; y + 1 < s.content.height; ++y) {
        for (int x = 1; x + 1 < s.content.width; ++x) uncovered_inside += screen.at(x, y)[0] < 0.999F ? 1 : 0;
    }
    EXPECT_EQ(uncovered_inside, 0);  // only the outermost content pixel ring may be uncovered
}

TEST(Composite, WrongBlendFailsTheCheck) {
    // Weights +0.1 inside every overlap: the sum is 1.1 at the overlap edges and 1.2 in the middle.
    ScreenCalibration s = make_ideal_calibration(IdealCalibrationParams{});
    const auto bands = ideal_bands(3, 0.15);
    for (auto& p : s.projectors) {
        for (std::size_t i = 0; i < p.blend.weight.size(); ++i) {
            const double u = p.warp.uv[2 * i];
            bool in_overlap = false;
            for (std::size_t k = 0; k + 1 < bands.size(); ++k) in_overlap |= u > bands[k + 1].u0 && u < bands[k].u1;
            if (in_overlap) p.blend.weight[i] = std::min(1.0F, p.blend.weight[i] + 0.1F);
        }
    }
    const RgbFloatImage content(s.content, 0.5F);
    const RgbFloatImage screen = composite_on_screen(s, render_all(s, content));
    const ImageDifference d = compare_images(screen, content, inner(s.content));
    EXPECT_GT(d.max_abs, kTolerance);
    EXPECT_NEAR(d.max_abs, 0.1, 0.005);  // 0.5 x (1.2 - 1)
    double worst_step = 0.0;
    for (const int column : overlap_edge_columns(s)) {
        for (int c = column - 1; c <= column + 1; ++c) {
            worst_step = std::max(worst_step, seam_step(screen, content, c, 2, s.content.height - 2));
        }
    }
    EXPECT_GT(worst_step, kTolerance);  // the seam check sees the 1.0 -> 1.1 step
}

TEST(Composite, MismatchedOutputsAreRejected) {
    IdealCalibrationParams p;
    p.output = {8, 6};
    p.content = {16, 6};
    const ScreenCalibration s = make_ideal_calibration(p);
    std::vector<RgbFloatImage> outputs(3, RgbFloatImage({8, 6}));
    outputs.pop_back();
    EXPECT_THROW((void)composite_on_screen(s, outputs), std::invalid_argument);
    outputs.emplace_back(ImageSize{8, 5});
    EXPECT_THROW((void)composite_on_screen(s, outputs), std::invalid_argument);
    EXPECT_THROW((void)render_output(s.projectors[0], RgbFloatImage()), std::invalid_argument);
}

TEST(RenderOutput, BlackOffsetIsAddedPerChannelAfterTheBlendAndBeforeTheResponse) {
    ScreenCalibration s = make_ideal_calibration(IdealCalibrationParams{});
    ProjectorCalibration p = s.projectors[1];
    p.beta.size = {2, 1};  // coarse grid: left sample, right sample
    p.beta.rgb = {0.01F, 0.02F, 0.03F, 0.05F, 0.0F, 0.5F};
    RgbFloatImage content(s.content, 0.25F);
    const RgbFloatImage out = render_output(p, content);
    const RgbFloatImage plain = render_output(s.projectors[1], content);
    const int y = p.output.height / 2;
    const int xl = 0;  // clamps to the left sample
    const int xr = p.output.width - 1;
    for (int c = 0; c < 3; ++c) {
        for (const int x : {xl, xr}) {
            const float weight = sample_blend(p.blend, p.output, x, y);
            const float beta = sample_beta(p.beta, p.output, x, y)[static_cast<std::size_t>(c)];
            EXPECT_NEAR(out.at(x, y)[c], apply_response(p.response, c, 0.25F * weight + beta), 1e-6F);
        }
        EXPECT_GT(out.at(xl, y)[c], plain.at(xl, y)[c]);
    }
    EXPECT_NEAR(sample_beta(p.beta, p.output, xl, y)[2], 0.03F, 1e-6F);
    EXPECT_NEAR(sample_beta(p.beta, p.output, xr, y)[2], 0.5F, 1e-6F);
    p.beta.rgb[4] = 1.5F;  // outside [0, 1]: refused by name
    try {
        (void)render_output(p, content);
        FAIL() << "beta 1.5 accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find(".beta"), std::string::npos) << e.what();
    }
}

// The screen's own light (Bimber et al., IEEE VR 2006) comes off the content at the warp's content
// point, bilinear over the field at texel centres, before the blend; beta is still added after.
TEST(RenderOutput, IndirectLightIsTakenOffTheContentBeforeTheBlend) {
    IdealCalibrationParams params;
    params.projectors = 1;
    params.output = {8, 4};
    params.content = {8, 4};
    ProjectorCalibration p = make_ideal_calibration(params).projectors[0];
    p.blend.weight[5] = 0.5F;  // output pixel (5, 0)
    p.warp.uv[2 * 6] = NAN;    // output pixel (6, 0): no content
    p.warp.uv[2 * 6 + 1] = NAN;
    p.beta.size = {1, 1};
    p.beta.rgb = {0.01F, 0.02F, 0.03F};
    const RgbFloatImage content = test_content(params.content);
    RgbFloatImage field({2, 1});  // texel centres at u = 0.25 and 0.75; blue of texel 1 beyond any content
    field.pixels = {0.1F, 0.2F, 0.05F, 0.3F, 0.0F, 5.0F};
    const RgbFloatImage out = render_output(p, content, field);
    // Output pixel x lands on content pixel x, u = (x + 0.5) / 8: field position u * 2 - 0.5,
    // clamped to [0, 1] (the edge texels' values beyond their centres).
    const std::pair<int, double> at_field[] = {{0, 0.0}, {3, 0.375}, {4, 0.625}, {5, 0.875}, {7, 1.0}};
    for (const auto& [x, f] : at_field) {
        for (int c = 0; c < 3; ++c) {
            const auto cu = static_cast<std::size_t>(c);
            const double indirect = field.pixels[cu] * (1.0 - f) + field.pixels[3 + cu] * f;
            const double linear = std::max(content.at(x, 0)[c] - indirect, 0.0) * (x == 5 ? 0.5 : 1.0);
            EXPECT_NEAR(out.at(x, 0)[c], apply_response(p.response, c, static_cast<float>(linear + p.beta.rgb[cu])),
                        1e-6F)
                << "pixel " << x << " channel " << c;
        }
    }
    // Where the field exceeds the content the pixel shows the black level (beta) alone.
    EXPECT_EQ(out.at(7, 0)[2], apply_response(p.response, 2, 0.03F));
    EXPECT_EQ(out.at(5, 0)[2], apply_response(p.response, 2, 0.03F));
    EXPECT_LT(out.at(3, 0)[0], render_output(p, content).at(3, 0)[0]);
    EXPECT_EQ(out.at(6, 0)[0], 0.0F);  // no content stays black, field or not
    // A 1x1 field is a constant.
    RgbFloatImage constant({1, 1});
    constant.pixels = {0.1F, 0.2F, 0.05F};
    const RgbFloatImage flat = render_output(p, content, constant);
    EXPECT_NEAR(flat.at(7, 2)[1],
                apply_response(p.response, 1, std::max(content.at(7, 2)[1] - 0.2F, 0.0F) + p.beta.rgb[1]), 1e-6F);
}

TEST(RenderOutput, EmptyIndirectLightIsTheCallWithout) {
    IdealCalibrationParams params;
    params.output = {96, 64};
    params.content = {240, 80};
    const ScreenCalibration s = make_ideal_calibration(params);
    const RgbFloatImage content = test_content(s.content);
    for (const ProjectorCalibration& p : s.projectors) {
        const RgbFloatImage plain = render_output(p, content);
        EXPECT_EQ(render_output(p, content, RgbFloatImage{}).pixels, plain.pixels);
        EXPECT_EQ(render_output(p, content, RgbFloatImage({3, 2}, 0.0F)).pixels, plain.pixels);  // zero light
    }
}

TEST(RenderOutput, BadIndirectLightIsRefusedByName) {
    const ProjectorCalibration p = make_ideal_calibration(IdealCalibrationParams{}).projectors[0];
    const RgbFloatImage content(ImageSize{16, 8}, 0.5F);
    const auto refused = [&](const RgbFloatImage& field, const std::string& says) {
        try {
            (void)render_output(p, content, field);
            ADD_FAILURE() << "accepted a field that should say " << says;
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find("indirect light field"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
        }
    };
    RgbFloatImage field({7, 3}, 0.1F);
    field.at(2, 1)[1] = NAN;
    refused(field, "at (2, 1) channel 1, must be finite and >= 0");
    field.at(2, 1)[1] = -0.01F;
    refused(field, "at (2, 1) channel 1, must be finite and >= 0");
    field.at(2, 1)[1] = INFINITY;
    refused(field, "must be finite and >= 0");
    field = RgbFloatImage({7, 3}, 0.1F);
    field.pixels.pop_back();
    refused(field, "expected");
    field = RgbFloatImage({0, 3});
    refused(field, "size 0x3");
}

}  // namespace
}  // namespace mogao
