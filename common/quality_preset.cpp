// SPDX-License-Identifier: Apache-2.0
#include "common/quality_preset.h"

#include <array>

namespace mogao {
namespace {

// Quality{spp, max_bounces, ao_samples, area_light_samples, resolution_scale, jpeg_quality}.
constexpr std::array kPresets{
    QualityPreset{"interactive", Quality{1, 0, 0, 1, 1.0, 80}, 1000.0 / 15.0, true, 256},
    QualityPreset{"balanced", Quality{2, 1, 1, 1, 1.0, 85}, 150.0, true, 1024},
    QualityPreset{"exhibit", Quality{4, 2, 2, 2, 1.0, 92}, 0.0, true, 4096},
};

}  // namespace

std::span<const QualityPreset> quality_presets() { return kPresets; }

const QualityPreset* quality_preset(std::string_view name) {
    for (const QualityPreset& p : kPresets)
        if (p.name == name) return &p;
    return nullptr;
}

std::string quality_preset_names() {
    std::string out;
    for (const QualityPreset& p : kPresets) {
        if (!out.empty()) out += ", ";
        out += p.name;
    }
    return out;
}

}  // namespace mogao
