// SPDX-License-Identifier: Apache-2.0
#include "kiosk/display/frame_indirect_light.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <system_error>

#include <fmt/format.h>

#include "appliance/autocal/model_store.h"
#include "common/srgb.h"

namespace mogao {

RgbFloatImage FrameIndirectLight::field(const Rgb8Image& frame, const ContentTransform& transform) const {
    const ImageSize s = frame.size;
    if (s.width <= 0 || s.height <= 0 || frame.pixels.size() != static_cast<std::size_t>(s.pixel_count()) * 3)
        return {};
    constexpr int kSamples = 4;
    const std::array<float, 256>& linear = srgb8_decode_table();
    const int columns = model_.columns(), rows = model_.rows();
    RgbFloatImage means(ImageSize{columns, rows});
    for (int r = 0; r < rows; ++r) {
        for (int c = 0; c < columns; ++c) {
            std::array<float, 3> sum{};
            for (int j = 0; j < kSamples; ++j) {
                for (int i = 0; i < kSamples; ++i) {
                    const double u = (c + (i + 0.5) / kSamples) / columns * transform.scale_u + transform.offset_u;
                    const double v = (r + (j + 0.5) / kSamples) / rows * transform.scale_v + transform.offset_v;
                    const int x = std::clamp(static_cast<int>(std::floor(u * s.width)), 0, s.width - 1);
                    const int y = std::clamp(static_cast<int>(std::floor(v * s.height)), 0, s.height - 1);
                    const std::uint8_t* px = frame.at(x, y);
                    for (std::size_t ch = 0; ch < 3; ++ch) sum[ch] += linear[px[ch]];
                }
            }
            float* m = means.at(c, r);
            for (std::size_t ch = 0; ch < 3; ++ch) m[ch] = sum[ch] / (kSamples * kSamples);
        }
    }
    return model_.field(means);
}

std::optional<FrameIndirectLight> load_frame_indirect_light(const std::filesystem::path& models,
                                                            const ScreenCalibration& screen, std::string* note) {
    const auto say = [&](std::string text) {
        if (note != nullptr) *note = std::move(text);
        return std::nullopt;
    };
    std::error_code ec;
    if (!std::filesystem::exists(models, ec))
        return say(fmt::format("the screen's own light is left on the picture: no models file {}", models.string()));
    try {
        const autocal::CalibrationModels m = autocal::read_models(models);
        autocal::IndirectLight model(m.screen, m.projectors, screen);
        if (!model.active())
            return say(
                fmt::format("the screen's own light is left on the picture: {} gives the screen a reflectance "
                            "of {:.3f} for it, below {}",
                            models.string(), m.screen.interreflection, autocal::IndirectLight::kMinReflectance));
        if (note != nullptr)
            *note = fmt::format(
                "the screen's own light (reflectance {:.3f}, {}) is taken off each frame over {}x{} "
                "patches",
                m.screen.interreflection, models.string(), model.columns(), model.rows());
        return FrameIndirectLight(std::move(model));
    } catch (const std::exception& e) {
        return say(fmt::format("the screen's own light is left on the picture: {}", e.what()));
    }
}

}  // namespace mogao
