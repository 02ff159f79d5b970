// SPDX-License-Identifier: Apache-2.0
#include "common/quality_preset.h"

#include <array>

namespace mogao {
namespace {

// Quality{spp, max_bounces, ao_samples, area_light_samples, resolution_scale, jpeg_quality}, then
// frame_time_ms, progressive, converged_spp, denoise, chroma_444. Chosen from the curves of
// docs/quality.md ("Presets"), where bench/quality measures exactly these rows.
constexpr std::array kPresets{
    QualityPreset{"interactive", Quality{1, 1, 0, 1, 1.0, 80}, 1000.0 / 15.0, true, 256, true, false, true},
    QualityPreset{"balanced", Quality{4, 2, 0, 1, 1.0, 85}, 150.0, true, 1024, true, false, true},
    QualityPreset{"exhibit", Quality{64, 4, 0, 1, 1.0, 95}, 0.0, true, 4096, false, true, false},
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
