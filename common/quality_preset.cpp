// SPDX-License-Identifier: Apache-2.0
#include "common/quality_preset.h"

#include <array>

namespace mogao {
namespace {

// Quality{spp, max_bounces, ao_samples, area_light_samples, resolution_scale, jpeg_quality}, then the
// serve fields by name (a positional list once shifted a flag into its neighbour's place). Chosen from
// the curves of docs/quality.md ("Presets"), where bench/quality measures exactly these rows.
constexpr std::array kPresets{
    QualityPreset{.name = "interactive",
                  .request = Quality{1, 1, 0, 1, 1.0, 80},
                  .frame_time_ms = 1000.0 / 15.0,
                  .progressive = true,
                  .converged_spp = 256,
                  .denoise = true,
                  .radiance_cache = true,
                  .follow_request_pace = true,
                  .chroma_444 = false},
    QualityPreset{.name = "balanced",
                  .request = Quality{4, 2, 0, 1, 1.0, 85},
                  .frame_time_ms = 150.0,
                  .progressive = true,
                  .converged_spp = 1024,
                  .denoise = true,
                  .radiance_cache = true,
                  .follow_request_pace = true,
                  .chroma_444 = false},
    QualityPreset{.name = "exhibit",
                  .request = Quality{64, 4, 0, 1, 1.0, 95},
                  .frame_time_ms = 0.0,
                  .progressive = true,
                  .converged_spp = 4096,
                  .denoise = false,
                  .radiance_cache = false,
                  .follow_request_pace = false,
                  .chroma_444 = true},
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
