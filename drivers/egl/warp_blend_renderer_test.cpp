// SPDX-License-Identifier: Apache-2.0
// WarpBlendRenderer against a CPU reference written here (reference_render, a pure function of
// the content and the calibration, in double precision), plus hand-computed expectations for
// the properties that matter on the wall: orientation, half-pixel sampling, NaN = black,
// attenuation in linear light, the response LUT, and a golden PNG.
#include "drivers/egl/warp_blend_renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <thread>
#include <utility>

#include "common/png_io.h"
#include "drivers/egl/egl_test_support.h"
#include "drivers/egl/test_pattern.h"

namespace mogao {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

double srgb_decode(std::uint8_t code) {
    const double e = code / 255.0;
    return e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4);
}

double srgb_encode(double x) { return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055; }

int to_code(double x) { return static_cast<int>(std::lround(std::clamp(x, 0.0, 1.0) * 255.0)); }

// Bilinear taps in texel-centre coordinates with edge clamping, as docs/outputs.md specifies.
struct Taps {
    int x0, y0, x1, y1;
    double fx, fy;
    [[nodiscard]] double w(int k) const {
        const double wx = (k & 1) != 0 ? fx : 1.0 - fx;
        const double wy = (k & 2) != 0 ? fy : 1.0 - fy;
        return wx * wy;
    }
    [[nodiscard]] int x(int k) const { return (k & 1) != 0 ? x1 : x0; }
    [[nodiscard]] int y(int k) const { return (k & 2) != 0 ? y1 : y0; }
};

Taps taps_at(double qx, double qy, ImageSize size) {
    const double bx = std::floor(qx);
    const double by = std::floor(qy);
    const auto ix = static_cast<int>(bx);
    const auto iy = static_cast<int>(by);
    return {std::clamp(ix, 0, size.width - 1),
            std::clamp(iy, 0, size.height - 1),
            std::clamp(ix + 1, 0, size.width - 1),
            std::clamp(iy + 1, 0, size.height - 1),
            qx - bx,
            qy - by};
}

std::size_t at(ImageSize s, int x, int y) {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(s.width) + static_cast<std::size_t>(x);
}

// The screen's own light at the warp's content point (u, v): bilinear at texel centres
// (i + 0.5) / W with edge clamping, sample_content's convention; 0 without a field.
std::array<double, 3> indirect_at(const RgbFloatImage& field, double u, double v) {
    std::array<double, 3> light{};
    if (field.size.width == 0) return light;
    const Taps t = taps_at(u * field.size.width - 0.5, v * field.size.height - 0.5, field.size);
    for (int k = 0; k < 4; ++k) {
        for (std::size_t ch = 0; ch < 3; ++ch) light[ch] += t.w(k) * field.at(t.x(k), t.y(k))[ch];
    }
    return light;
}

// The CPU reference: see the maths in warp_blend_renderer.h.
Rgb8Image reference_render(const Rgb8Image& content, const ProjectorCalibration& c,
                           const WarpBlendRenderer::ContentTransform& late = {}, const RgbFloatImage& indirect = {}) {
    Rgb8Image out(c.output);
    // Scales in float, as the renderer passes them to the shader.
    const double wsx = static_cast<float>(c.warp.size.width) / static_cast<float>(c.output.width);
    const double wsy = static_cast<float>(c.warp.size.height) / static_cast<float>(c.output.height);
    const double bsx = static_cast<float>(c.blend.size.width) / static_cast<float>(c.output.width);
    const double bsy = static_cast<float>(c.blend.size.height) / static_cast<float>(c.output.height);
    const std::size_t n = c.response.lut[0].size();
    for (int y = 0; y < c.output.height; ++y) {
        for (int x = 0; x < c.output.width; ++x) {
            const double px = x + 0.5;
            const double py = y + 0.5;
            const Taps wt = taps_at(px * wsx - 0.5, py * wsy - 0.5, c.warp.size);
            double u = 0.0;
            double v = 0.0;
            bool black = false;
            for (int k = 0; k < 4; ++k) {
                const float* t = &c.warp.uv[at(c.warp.size, wt.x(k), wt.y(k)) * 2];
                const bool valid = std::isfinite(t[0]) && std::isfinite(t[1]);
                if (!valid) {
                    black = black || wt.w(k) > 0.0;
                    continue;
                }
                u += wt.w(k) * std::clamp(static_cast<double>(t[0]), -1.0, 2.0);
                v += wt.w(k) * std::clamp(static_cast<double>(t[1]), -1.0, 2.0);
            }
            std::uint8_t* dst = out.at(x, y);
            if (black) {
                dst[0] = dst[1] = dst[2] = 0;
                continue;
            }
            const Taps bt = taps_at(px * bsx - 0.5, py * bsy - 0.5, c.blend.size);
            double weight = 0.0;
            for (int k = 0; k < 4; ++k) weight += bt.w(k) * c.blend.weight[at(c.blend.size, bt.x(k), bt.y(k))];
            double beta[3] = {0.0, 0.0, 0.0};
            if (c.beta.size.width > 0) {
                const double tsx = static_cast<float>(c.beta.size.width) / static_cast<float>(c.output.width);
                const double tsy = static_cast<float>(c.beta.size.height) / static_cast<float>(c.output.height);
                const Taps t = taps_at(px * tsx - 0.5, py * tsy - 0.5, c.beta.size);
                for (int k = 0; k < 4; ++k) {
                    for (int ch = 0; ch < 3; ++ch)
                        beta[ch] += t.w(k) * c.beta.rgb[at(c.beta.size, t.x(k), t.y(k)) * 3 + ch];
                }
            }
            const std::array<double, 3> screen_light = indirect_at(indirect, u, v);  // before the late warp
            u = u * double{late.scale_u} + double{late.offset_u};  // the late warp's map (float inputs)
            v = v * double{late.scale_v} + double{late.offset_v};
            const Taps ct = taps_at(u * content.size.width - 0.5, v * content.size.height - 0.5, content.size);
            for (int ch = 0; ch < 3; ++ch) {
                double linear = 0.0;
                for (int k = 0; k < 4; ++k) linear += ct.w(k) * srgb_decode(content.at(ct.x(k), ct.y(k))[ch]);
                linear = std::max(linear - screen_light[static_cast<std::size_t>(ch)], 0.0);
                const double pos = std::clamp(linear * weight + beta[ch], 0.0, 1.0) * static_cast<double>(n - 1);
                const auto i = std::min(static_cast<std::size_t>(pos), n - 2);
                const double f = pos - static_cast<double>(i);
                const auto& lut = c.response.lut[static_cast<std::size_t>(ch)];
                dst[ch] = static_cast<std::uint8_t>(to_code(lut[i] * (1.0 - f) + lut[i + 1] * f));
            }
        }
    }
    return out;
}

struct Diff {
    int max = 0;
    int x = -1, y = -1;
};

Diff max_abs_diff(const Rgb8Image& a, const Rgb8Image& b) {
    Diff d;
    EXPECT_EQ(a.size, b.size);
    if (!(a.size == b.size)) return {255, 0, 0};
    for (int y = 0; y < a.size.height; ++y) {
        for (int x = 0; x < a.size.width; ++x) {
            for (int ch = 0; ch < 3; ++ch) {
                const int diff = std::abs(int{a.at(x, y)[ch]} - int{b.at(x, y)[ch]});
                if (diff > d.max) d = {diff, x, y};
            }
        }
    }
    return d;
}

// Deterministic busy content (LCG), every channel using the full 0..255 range.
Rgb8Image noise_content(ImageSize size, std::uint32_t seed) {
    Rgb8Image img(size);
    for (auto& v : img.pixels) {
        seed = seed * 1664525u + 1013904223u;
        v = static_cast<std::uint8_t>(seed >> 24);
    }
    return img;
}

Rgb8Image uniform_content(ImageSize size, std::uint8_t value) { return Rgb8Image(size, value); }

ProjectorCalibration with_uniform_blend(ProjectorCalibration c, float weight) {
    c.blend.size = {1, 1};
    c.blend.weight = {weight};
    return c;
}

// A coarse (1/8 resolution) black offset, brighter to the right (the overlap) and per channel.
BlackOffset ramp_beta(ImageSize output) {
    BlackOffset b;
    b.size = {output.width / 8, output.height / 8};
    b.rgb.resize(static_cast<std::size_t>(b.size.pixel_count()) * 3);
    for (int y = 0; y < b.size.height; ++y) {
        for (int x = 0; x < b.size.width; ++x) {
            const double t = (x + 0.5) / b.size.width;
            for (int ch = 0; ch < 3; ++ch) {
                b.rgb[at(b.size, x, y) * 3 + static_cast<std::size_t>(ch)] =
                    static_cast<float>((0.002 + 0.01 * t) * (1.0 + 0.5 * ch) + 0.001 * y);
            }
        }
    }
    return b;
}

// A realistic calibration: a coarse (1/4 resolution) barrel-ish warp over part of the content
// with a NaN patch, a coarse blend ramp (edge blend on the right), a different gamma per channel.
ProjectorCalibration busy_calibration(ImageSize output) {
    ProjectorCalibration c;
    c.id = "busy";
    c.output = output;
    c.warp.size = {output.width / 4, output.height / 4};
    c.warp.uv.resize(static_cast<std::size_t>(c.warp.size.pixel_count()) * 2);
    for (int y = 0; y < c.warp.size.height; ++y) {
        for (int x = 0; x < c.warp.size.width; ++x) {
            const double sx = (x + 0.5) / c.warp.size.width - 0.5;  // -0.5..0.5
            const double sy = (y + 0.5) / c.warp.size.height - 0.5;
            const double r2 = sx * sx + sy * sy;
            float* t = &c.warp.uv[at(c.warp.size, x, y) * 2];
            t[0] = static_cast<float>(0.55 + 0.8 * sx * (1.0 + 0.3 * r2));
            t[1] = static_cast<float>(0.5 + 0.9 * sy * (1.0 + 0.3 * r2) + 0.05 * sx);
            if (x < 3 && y < 2) t[0] = t[1] = kNaN;  // outside the screen
        }
    }
    c.blend.size = {output.width / 8, 3};
    c.blend.weight.resize(static_cast<std::size_t>(c.blend.size.pixel_count()));
    for (int y = 0; y < c.blend.size.height; ++y) {
        for (int x = 0; x < c.blend.size.width; ++x) {
            const double t = std::clamp((x + 0.5) / c.blend.size.width * 3.0 - 1.5, 0.0, 1.0);
            c.blend.weight[at(c.blend.size, x, y)] = static_cast<float>(1.0 - t * (0.6 + 0.1 * y));
        }
    }
    const double gammas[3] = {1.8, 2.2, 2.6};
    for (std::size_t ch = 0; ch < 3; ++ch) c.response.lut[ch] = gamma_response(gammas[ch], 257).lut[ch];
    return c;
}

class WarpBlendRendererTest : public mogao::testing::GlTest {
protected:
    void SetUp() override {
        GlTest::SetUp();
        if (IsSkipped() || HasFatalFailure()) return;
        auto r = WarpBlendRenderer::create();
        ASSERT_TRUE(r) << r.error().message;
        renderer_.emplace(std::move(r.value()));
    }
    void TearDown() override {
        renderer_.reset();  // while the context is current
        GlTest::TearDown();
    }

    Rgb8Image render(const Rgb8Image& content, const ProjectorCalibration& c) {
        EXPECT_TRUE(renderer_->set_content(content).ok());
        auto index = renderer_->add_projector(c);
        EXPECT_TRUE(index) << index.error().message;
        if (!index) return {};
        auto image = renderer_->render(index.value());
        EXPECT_TRUE(image) << image.error().message;
        return image ? std::move(image).value() : Rgb8Image{};
    }

    std::optional<WarpBlendRenderer> renderer_;
};

TEST_F(WarpBlendRendererTest, IdentityReproducesContent) {
    const ImageSize size{37, 23};  // odd sizes: no accidental power-of-two exactness
    const Rgb8Image content = noise_content(size, 1);
    const Rgb8Image out = render(content, identity_calibration("p0", size));
    const Diff d = max_abs_diff(out, content);
    EXPECT_LE(d.max, 1) << "at (" << d.x << ", " << d.y << ")";
}

TEST_F(WarpBlendRendererTest, WholePixelShiftKeepsOrientation) {
    // Content column x has red = 10 * x, row y has green = 20 * y; sampling at content pixel
    // (x + 1, y + 1) must give output (x, y) those values: catches flipped rows or columns.
    const ImageSize content_size{16, 8};
    Rgb8Image content(content_size);
    for (int y = 0; y < content_size.height; ++y) {
        for (int x = 0; x < content_size.width; ++x) {
            content.at(x, y)[0] = static_cast<std::uint8_t>(10 * x);
            content.at(x, y)[1] = static_cast<std::uint8_t>(20 * y);
            content.at(x, y)[2] = 77;
        }
    }
    ProjectorCalibration c = identity_calibration("shift", {15, 7});
    for (int y = 0; y < 7; ++y) {
        for (int x = 0; x < 15; ++x) {
            c.warp.uv[at(c.warp.size, x, y) * 2] = static_cast<float>((x + 1.5) / 16.0);
            c.warp.uv[at(c.warp.size, x, y) * 2 + 1] = static_cast<float>((y + 1.5) / 8.0);
        }
    }
    const Rgb8Image out = render(content, c);
    for (int y = 0; y < 7; ++y) {
        for (int x = 0; x < 15; ++x) {
            EXPECT_NEAR(out.at(x, y)[0], 10 * (x + 1), 1) << x << "," << y;
            EXPECT_NEAR(out.at(x, y)[1], 20 * (y + 1), 1) << x << "," << y;
            EXPECT_NEAR(out.at(x, y)[2], 77, 1) << x << "," << y;
        }
    }
}

TEST_F(WarpBlendRendererTest, HalfPixelShiftAveragesNeighboursInLinearLight) {
    // Columns alternate black/white; sampling halfway between two column centres gives linear
    // 0.5, which the sRGB response encodes as 188 -- not 128, the average of the codes.
    const ImageSize content_size{16, 4};
    Rgb8Image content(content_size);
    for (int y = 0; y < 4; ++y) {
        for (int x = 0; x < 16; ++x) std::fill_n(content.at(x, y), 3, static_cast<std::uint8_t>(x % 2 == 0 ? 0 : 255));
    }
    ProjectorCalibration c = identity_calibration("half", {15, 4});
    for (int y = 0; y < 4; ++y) {
        for (int x = 0; x < 15; ++x) {
            c.warp.uv[at(c.warp.size, x, y) * 2] = static_cast<float>((x + 1.0) / 16.0);  // between x and x+1
            c.warp.uv[at(c.warp.size, x, y) * 2 + 1] = static_cast<float>((y + 0.5) / 4.0);
        }
    }
    const Rgb8Image out = render(content, c);
    ASSERT_EQ(to_code(srgb_encode(0.5)), 188);
    for (int y = 0; y < 4; ++y) {
        for (int x = 0; x < 15; ++x) EXPECT_NEAR(out.at(x, y)[1], 188, 1) << x << "," << y;
    }
}

TEST_F(WarpBlendRendererTest, NaNWarpGivesBlackEvenWithLiftedResponse) {
    const ImageSize size{20, 10};
    ProjectorCalibration c = identity_calibration("nan", size);
    for (int y = 2; y < 6; ++y) {
        for (int x = 3; x < 9; ++x) {
            c.warp.uv[at(size, x, y) * 2] = kNaN;
            c.warp.uv[at(size, x, y) * 2 + 1] = kNaN;
        }
    }
    for (auto& channel : c.response.lut) {
        for (auto& v : channel) v = 0.2f + 0.8f * v;  // black level 0.2: NaN must still be 0
    }
    const Rgb8Image out = render(uniform_content(size, 200), c);
    for (int y = 0; y < size.height; ++y) {
        for (int x = 0; x < size.width; ++x) {
            const bool inside = x >= 3 && x < 9 && y >= 2 && y < 6;
            const int expected = inside ? 0 : to_code(0.2 + 0.8 * (200 / 255.0));
            EXPECT_NEAR(out.at(x, y)[0], expected, 1) << x << "," << y;
        }
    }
}

TEST_F(WarpBlendRendererTest, BlendHalvesLinearLightNotCodes) {
    const ImageSize size{8, 8};
    const Rgb8Image out = render(uniform_content(size, 200), with_uniform_blend(identity_calibration("b", size), 0.5f));
    const int expected = to_code(srgb_encode(0.5 * srgb_decode(200)));
    ASSERT_EQ(expected, 146);  // 200 -> linear 0.578 -> 0.289 -> sRGB 146 (half the code would be 100)
    for (int y = 0; y < size.height; ++y) {
        for (int x = 0; x < size.width; ++x) {
            for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(out.at(x, y)[ch], expected, 1);
        }
    }
}

TEST_F(WarpBlendRendererTest, Gamma22ResponseIsApplied) {
    const ImageSize size{256, 1};
    Rgb8Image ramp(size);
    for (int x = 0; x < 256; ++x) std::fill_n(ramp.at(x, 0), 3, static_cast<std::uint8_t>(x));
    ProjectorCalibration c = identity_calibration("g", size);
    c.response = gamma_response(2.2, 1024);
    const Rgb8Image out = render(ramp, c);
    const Diff d = max_abs_diff(out, reference_render(ramp, c));
    EXPECT_LE(d.max, 2) << "vs CPU reference at code " << d.x;
    for (int x = 16; x < 256; ++x) {
        const int analytic = to_code(std::pow(srgb_decode(static_cast<std::uint8_t>(x)), 1.0 / 2.2));
        EXPECT_NEAR(out.at(x, 0)[0], analytic, 2) << "code " << x;
    }
    // Where gamma 2.2 and sRGB differ most (dark codes), the output is not the identity.
    for (int x = 10; x <= 30; ++x) EXPECT_GE(out.at(x, 0)[0], x + 3) << "code " << x;
}

// The late rotational warp (appliance/warp/late_warp.h): a guarded frame 340 columns wide for a
// 300-column screen (20 each side), shifted by 4 columns. The draw matches the CPU reference with
// the same map, and equals drawing the 300 columns starting at 16 cut out on the CPU.
TEST_F(WarpBlendRendererTest, ContentTransformShiftsLikeTheCpuReference) {
    const Rgb8Image guarded = noise_content({340, 30}, 11);
    WarpBlendRenderer::ContentTransform t;
    t.scale_u = 300.0f / 340.0f;
    t.offset_u = 16.0f / 340.0f;
    const ProjectorCalibration busy = busy_calibration({64, 48});
    renderer_->set_content_transform(t);
    const Rgb8Image out = render(guarded, busy);
    Diff d = max_abs_diff(out, reference_render(guarded, busy, t));
    EXPECT_LE(d.max, 2) << "at (" << d.x << ", " << d.y << ")";

    Rgb8Image window({300, 30});
    for (int y = 0; y < 30; ++y) {
        for (int x = 0; x < 300; ++x) {
            for (int ch = 0; ch < 3; ++ch) window.at(x, y)[ch] = guarded.at(x + 16, y)[ch];
        }
    }
    const ProjectorCalibration identity = identity_calibration("window", {300, 30});
    const Rgb8Image shifted = render(guarded, identity);
    renderer_->set_content_transform({});
    const Rgb8Image cut = render(window, identity);
    d = max_abs_diff(shifted, cut);
    EXPECT_LE(d.max, 1) << "at (" << d.x << ", " << d.y << ")";
    d = max_abs_diff(cut, window);
    EXPECT_LE(d.max, 1) << "identity transform: the content itself, at (" << d.x << ", " << d.y << ")";
}

TEST_F(WarpBlendRendererTest, BusyCalibrationMatchesCpuReference) {
    const Rgb8Image content = noise_content({80, 50}, 7);
    const ProjectorCalibration c = busy_calibration({64, 48});
    const Rgb8Image out = render(content, c);
    const Diff d = max_abs_diff(out, reference_render(content, c));
    EXPECT_LE(d.max, 2) << "at (" << d.x << ", " << d.y << ")";
    EXPECT_EQ(out.at(0, 0)[0], 0);  // inside the NaN patch
}

// An output whose mode differs from the calibration's output size (a 640x480 calibration on a
// 1024x768 mode): the whole target is the calibrated picture resampled, not a corner of it.
TEST_F(WarpBlendRendererTest, DrawIntoLargerOrSmallerTargetResamplesTheWholePicture) {
    const Rgb8Image content = noise_content({80, 50}, 11);
    const ProjectorCalibration c = busy_calibration({64, 48});
    ASSERT_TRUE(renderer_->set_content(content).ok());
    auto index = renderer_->add_projector(c);
    ASSERT_TRUE(index) << index.error().message;
    for (const ImageSize target : {ImageSize{101, 77}, ImageSize{40, 30}}) {
        auto fbo = make_render_target(target);
        ASSERT_TRUE(fbo) << fbo.error().message;
        glBindFramebuffer(GL_FRAMEBUFFER, fbo->fbo.get());
        ASSERT_TRUE(renderer_->draw(*index, target).ok());
        Rgb8Image out(target);
        std::vector<std::uint8_t> scratch;
        ASSERT_TRUE(read_rgb8(target, out, scratch).ok());
        ProjectorCalibration as_target = c;
        as_target.output = target;  // the reference's output pixel grid is the target's
        const Diff d = max_abs_diff(out, reference_render(content, as_target));
        EXPECT_LE(d.max, 2) << target.width << "x" << target.height << " at (" << d.x << ", " << d.y << ")";
        // The far corner is drawn (a corner-only draw would leave it at the cleared value).
        const std::uint8_t* far = out.at(target.width - 1, target.height - 1);
        EXPECT_GT(int{far[0]} + far[1] + far[2], 0);
    }
    EXPECT_FALSE(renderer_->draw(*index, ImageSize{0, 10}).ok());
}

// Beta is added in linear light after the blend and before the LUT, also where the content is
// black; the channels get their own offsets.
TEST_F(WarpBlendRendererTest, BetaLiftsBlackBeforeTheResponse) {
    const ImageSize size{12, 6};
    ProjectorCalibration c = with_uniform_blend(identity_calibration("beta", size), 0.5f);
    c.response = gamma_response(2.2, 4096);
    c.beta.size = {1, 1};
    c.beta.rgb = {0.004f, 0.01f, 0.03f};
    const Rgb8Image black = render(uniform_content(size, 0), c);
    const Rgb8Image grey = render(uniform_content(size, 200), c);
    for (int ch = 0; ch < 3; ++ch) {
        const double b = c.beta.rgb[static_cast<std::size_t>(ch)];
        EXPECT_NEAR(black.at(5, 3)[ch], to_code(std::pow(b, 1.0 / 2.2)), 1) << "channel " << ch;
        EXPECT_NEAR(grey.at(5, 3)[ch], to_code(std::pow(0.5 * srgb_decode(200) + b, 1.0 / 2.2)), 1) << "channel " << ch;
    }
    EXPECT_GE(black.at(0, 0)[2], 50);  // 0.03^(1/2.2) = 0.20: black is lifted, not 0
}

TEST_F(WarpBlendRendererTest, BusyCalibrationWithBetaMatchesCpuReference) {
    const Rgb8Image content = noise_content({80, 50}, 9);
    ProjectorCalibration c = busy_calibration({64, 48});
    c.beta = ramp_beta(c.output);
    const Rgb8Image out = render(content, c);
    Diff d = max_abs_diff(out, reference_render(content, c));
    EXPECT_LE(d.max, 2) << "at (" << d.x << ", " << d.y << ")";
    const Rgb8Image dark = render(uniform_content({80, 50}, 0), c);
    d = max_abs_diff(dark, reference_render(uniform_content({80, 50}, 0), c));
    EXPECT_LE(d.max, 2) << "black content, at (" << d.x << ", " << d.y << ")";
    EXPECT_GT(dark.at(40, 24)[0], 10);  // lifted black, visible in the output
    EXPECT_EQ(dark.at(0, 0)[0], 0);     // no content (NaN warp): black, beta or not
}

TEST_F(WarpBlendRendererTest, RejectsBadBetaNamingProjectorAndMap) {
    ProjectorCalibration c = identity_calibration("pb", {8, 8});
    c.beta.size = {4, 4};
    c.beta.rgb.assign(4 * 4 * 3 - 1, 0.0f);
    auto r = renderer_->add_projector(c);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.code(), EINVAL);
    EXPECT_NE(r.error().message.find("projector 'pb': beta map 4x4"), std::string::npos) << r.error().message;
    c.beta.rgb.assign(4 * 4 * 3, 0.0f);
    c.beta.rgb[5 * 3 + 2] = kNaN;
    r = renderer_->add_projector(c);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("beta map has a non-finite offset at (1, 1) channel 2"), std::string::npos)
        << r.error().message;
    c.beta.size = {0, 3};
    c.beta.rgb.clear();
    EXPECT_EQ(renderer_->add_projector(c).code(), EINVAL);
    c.beta.size = {1 << 20, 1};
    EXPECT_EQ(renderer_->add_projector(c).code(), E2BIG);
    EXPECT_EQ(renderer_->projector_count(), 0u);
    // A replace with a bad beta keeps the old calibration.
    auto ok = renderer_->add_projector(identity_calibration("pb", {8, 8}));
    ASSERT_TRUE(ok);
    EXPECT_FALSE(renderer_->replace_projector(*ok, c).ok());
    ASSERT_TRUE(renderer_->set_content(uniform_content({8, 8}, 0)).ok());
    auto out = renderer_->render(*ok);
    ASSERT_TRUE(out);
    EXPECT_EQ(max_abs_diff(*out, uniform_content({8, 8}, 0)).max, 0);
}

// A coarse screen-light field (7 x 3 texels over the content), brighter to the right and
// downwards, per channel: up to 0.44, so that dark content is clamped at 0 and bright is not.
RgbFloatImage gradient_field(float scale = 1.0f) {
    RgbFloatImage field({7, 3});
    for (int y = 0; y < 3; ++y) {
        for (int x = 0; x < 7; ++x) {
            for (int ch = 0; ch < 3; ++ch) {
                field.at(x, y)[ch] = scale * static_cast<float>(0.02 + 0.05 * x + 0.03 * y + 0.05 * ch);
            }
        }
    }
    return field;
}

// The screen's own light comes off the content before the blend, read at the warp's content
// point (not the late warp's): both shader variants (coarse maps and maps of the target's size)
// against the CPU reference, with and without a content transform.
TEST_F(WarpBlendRendererTest, IndirectLightIsTakenOffLikeTheCpuReference) {
    const Rgb8Image content = noise_content({80, 50}, 13);
    ProjectorCalibration busy = busy_calibration({64, 48});
    busy.beta = ramp_beta(busy.output);
    const RgbFloatImage field = gradient_field();
    const Rgb8Image without = render(content, busy);
    ASSERT_TRUE(renderer_->set_indirect_light(field).ok());
    EXPECT_EQ(renderer_->indirect_light_size(), (ImageSize{7, 3}));
    const Rgb8Image out = render(content, busy);
    Diff d = max_abs_diff(out, reference_render(content, busy, {}, field));
    EXPECT_LE(d.max, 2) << "coarse maps, at (" << d.x << ", " << d.y << ")";
    EXPECT_GT(max_abs_diff(out, without).max, 40);  // the field does change the picture

    ProjectorCalibration exact = identity_calibration("exact", {80, 50});
    exact.blend.size = {80, 50};  // every map the target's size: the exact-maps variant
    exact.blend.weight.assign(80 * 50, 0.9f);
    exact.beta = ramp_beta({640, 400});  // 80 x 50
    d = max_abs_diff(render(content, exact), reference_render(content, exact, {}, field));
    EXPECT_LE(d.max, 2) << "maps of the target's size, at (" << d.x << ", " << d.y << ")";

    WarpBlendRenderer::ContentTransform t;
    t.scale_u = 0.8f;
    t.offset_u = 0.15f;
    renderer_->set_content_transform(t);
    const Rgb8Image moved = render(content, busy);
    d = max_abs_diff(moved, reference_render(content, busy, t, field));
    EXPECT_LE(d.max, 2) << "content transform, at (" << d.x << ", " << d.y << ")";
    // Read at the transformed uv instead, the field would be 0.15 * 7 texels off: clearly different.
    RgbFloatImage shifted({7, 3});
    for (int y = 0; y < 3; ++y) {
        for (int x = 0; x < 7; ++x) std::copy_n(field.at(std::min(x + 1, 6), y), 3, shifted.at(x, y));
    }
    EXPECT_GT(max_abs_diff(moved, reference_render(content, busy, t, shifted)).max, 2);
}

// By hand: identity map, uniform content 200 (linear 0.578), blend 0.5, gamma 2.2, a constant
// (1x1) field; blue's field exceeds the content, so blue shows the black offset alone.
TEST_F(WarpBlendRendererTest, IndirectLightByHand) {
    const ImageSize size{12, 6};
    ProjectorCalibration c = with_uniform_blend(identity_calibration("hand", size), 0.5f);
    c.response = gamma_response(2.2, 4096);
    c.beta.size = {1, 1};
    c.beta.rgb = {0.004f, 0.01f, 0.03f};
    RgbFloatImage field({1, 1});
    field.pixels = {0.1f, 0.3f, 0.9f};
    ASSERT_TRUE(renderer_->set_indirect_light(field).ok());
    const Rgb8Image out = render(uniform_content(size, 200), c);
    for (int ch = 0; ch < 3; ++ch) {
        const auto chu = static_cast<std::size_t>(ch);
        const double linear = std::max(srgb_decode(200) - field.pixels[chu], 0.0) * 0.5 + c.beta.rgb[chu];
        for (const auto& [x, y] : {std::pair{0, 0}, std::pair{5, 3}, std::pair{11, 5}}) {
            EXPECT_NEAR(out.at(x, y)[ch], to_code(std::pow(linear, 1.0 / 2.2)), 1) << "channel " << ch;
        }
    }
    EXPECT_NEAR(out.at(5, 3)[2], to_code(std::pow(0.03, 1.0 / 2.2)), 1);  // black level only
}

// A new field of the same size every frame updates in place; an empty one draws exactly (bit for
// bit) what a renderer that never had a field draws.
TEST_F(WarpBlendRendererTest, IndirectLightUpdatesPerFrameAndEmptyIsNone) {
    const Rgb8Image content = noise_content({80, 50}, 17);
    ProjectorCalibration busy = busy_calibration({64, 48});
    busy.beta = ramp_beta(busy.output);
    const Rgb8Image before = render(content, busy);
    EXPECT_EQ(renderer_->indirect_light_size(), (ImageSize{0, 0}));
    for (const float scale : {1.0f, 0.3f, 1.6f}) {
        const RgbFloatImage field = gradient_field(scale);
        ASSERT_TRUE(renderer_->set_indirect_light(field).ok());
        const Diff d = max_abs_diff(render(content, busy), reference_render(content, busy, {}, field));
        EXPECT_LE(d.max, 2) << "field x" << scale << " at (" << d.x << ", " << d.y << ")";
    }
    ASSERT_TRUE(renderer_->set_indirect_light(RgbFloatImage{}).ok());
    EXPECT_EQ(renderer_->indirect_light_size(), (ImageSize{0, 0}));
    EXPECT_EQ(render(content, busy).pixels, before.pixels);
}

TEST_F(WarpBlendRendererTest, RejectsBadIndirectLightKeepingTheOldField) {
    const Rgb8Image content = noise_content({40, 30}, 19);
    const ProjectorCalibration c = busy_calibration({32, 24});
    const RgbFloatImage good = gradient_field();
    ASSERT_TRUE(renderer_->set_indirect_light(good).ok());
    const Rgb8Image with_good = render(content, c);
    const auto refused = [&](const RgbFloatImage& field, int code, const std::string& says) {
        const Status s = renderer_->set_indirect_light(field);
        ASSERT_FALSE(s.ok()) << says;
        EXPECT_EQ(s.code(), code) << s.error().message;
        EXPECT_NE(s.error().message.find(says), std::string::npos) << s.error().message;
    };
    RgbFloatImage bad = good;
    bad.at(3, 2)[1] = kNaN;
    refused(bad, EINVAL, "indirect light field has value nan at (3, 2) channel 1, must be finite and >= 0");
    bad.at(3, 2)[1] = -0.25f;
    refused(bad, EINVAL, "indirect light field has value -0.250000 at (3, 2) channel 1, must be finite and >= 0");
    bad.at(3, 2)[1] = std::numeric_limits<float>::infinity();
    refused(bad, EINVAL, "at (3, 2) channel 1, must be finite and >= 0");
    bad = good;
    bad.pixels.pop_back();
    refused(bad, EINVAL, "indirect light field 7x3 holds 62 values, expected width*height*3");
    refused(RgbFloatImage({0, 3}), EINVAL, "indirect light field size 0x3 is empty");
    bad = RgbFloatImage{};
    bad.size = {1 << 20, 1};
    refused(bad, E2BIG, "indirect light field size 1048576x1 exceeds GL_MAX_TEXTURE_SIZE");
    EXPECT_EQ(renderer_->indirect_light_size(), good.size);
    EXPECT_EQ(render(content, c).pixels, with_good.pixels);
}

TEST_F(WarpBlendRendererTest, MatchesGoldenPng) {
    // Regenerate with MOGAO_UPDATE_GOLDEN=1 after an intended change, and look at the file.
    const std::filesystem::path golden =
        std::filesystem::path(MOGAO_SOURCE_DIR) / "drivers/egl/testdata/warp_blend_golden.png";
    const Rgb8Image content = make_test_pattern({96, 64});
    const ProjectorCalibration c = busy_calibration({128, 96});
    const Rgb8Image out = render(content, c);
    EXPECT_LE(max_abs_diff(out, reference_render(content, c)).max, 2);
    if (std::getenv("MOGAO_UPDATE_GOLDEN") != nullptr) write_png(golden, out);
    ASSERT_TRUE(std::filesystem::exists(golden)) << golden << " is missing; run with MOGAO_UPDATE_GOLDEN=1";
    const Diff d = max_abs_diff(out, read_png(golden));
    EXPECT_LE(d.max, 2) << "at (" << d.x << ", " << d.y << ")";  // tolerance for other GPUs' rounding
}

TEST_F(WarpBlendRendererTest, ContentSizeMayChangeBetweenFrames) {
    const ImageSize size{12, 6};
    auto index = renderer_->add_projector(identity_calibration("p", size));
    ASSERT_TRUE(index);
    ASSERT_TRUE(renderer_->set_content(uniform_content({3, 3}, 40)).ok());
    ASSERT_TRUE(renderer_->render(*index));
    const Rgb8Image content = noise_content(size, 3);
    ASSERT_TRUE(renderer_->set_content(content).ok());
    auto out = renderer_->render(*index);
    ASSERT_TRUE(out);
    EXPECT_LE(max_abs_diff(*out, content).max, 1);
}

TEST_F(WarpBlendRendererTest, ProjectorsRenderIndependently) {
    const Rgb8Image content = noise_content({30, 20}, 5);
    ASSERT_TRUE(renderer_->set_content(content).ok());
    auto a = renderer_->add_projector(identity_calibration("a", {30, 20}));
    auto b = renderer_->add_projector(with_uniform_blend(identity_calibration("b", {30, 20}), 0.0f));
    ASSERT_TRUE(a && b);
    EXPECT_EQ(renderer_->projector_count(), 2u);
    auto out_b = renderer_->render(*b);
    auto out_a = renderer_->render(*a);
    ASSERT_TRUE(out_a && out_b);
    EXPECT_LE(max_abs_diff(*out_a, content).max, 1);
    EXPECT_EQ(max_abs_diff(*out_b, Rgb8Image({30, 20}, 0)).max, 0);
}

TEST_F(WarpBlendRendererTest, RejectsInconsistentInput) {
    ProjectorCalibration c = identity_calibration("bad", {8, 8});
    c.warp.uv.pop_back();
    auto r = renderer_->add_projector(c);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.code(), EINVAL);
    EXPECT_NE(r.error().message.find("projector 'bad': warp map 8x8"), std::string::npos) << r.error().message;

    c = identity_calibration("lut", {8, 8});
    c.response.lut[2].pop_back();
    EXPECT_EQ(renderer_->add_projector(c).code(), EINVAL);
    c.response.lut = {std::vector<float>{0.5f}, std::vector<float>{0.5f}, std::vector<float>{0.5f}};
    EXPECT_EQ(renderer_->add_projector(c).code(), EINVAL);

    c = with_uniform_blend(identity_calibration("inf", {8, 8}), std::numeric_limits<float>::infinity());
    EXPECT_EQ(renderer_->add_projector(c).code(), EINVAL);

    c = identity_calibration("huge", {8, 8});
    c.output = {1 << 20, 8};
    EXPECT_EQ(renderer_->add_projector(c).code(), E2BIG);

    EXPECT_EQ(renderer_->projector_count(), 0u);
    auto ok = renderer_->add_projector(identity_calibration("ok", {8, 8}));
    ASSERT_TRUE(ok);
    EXPECT_EQ(renderer_->render(*ok).code(), EINVAL);  // no content yet
    ASSERT_TRUE(renderer_->set_content(uniform_content({4, 4}, 1)).ok());
    EXPECT_EQ(renderer_->render(7).code(), EINVAL);
    Rgb8Image short_frame({4, 4});
    short_frame.pixels.pop_back();
    EXPECT_EQ(renderer_->set_content(short_frame).code(), EINVAL);
}

TEST(WarpBlendRenderer, CreateWithoutCurrentContextIsAnError) {
    int code = 0;
    std::thread([&] { code = WarpBlendRenderer::create().code(); }).join();  // a thread has no context
    EXPECT_EQ(code, EINVAL);
}

}  // namespace
}  // namespace mogao
