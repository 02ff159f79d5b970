// SPDX-License-Identifier: Apache-2.0
#include "kiosk/display/projector_assignment.h"

#include <fmt/format.h>

namespace mogao {

std::vector<std::optional<std::size_t>> assign_projectors(const std::vector<OutputInfo>& outputs,
                                                          const ScreenCalibration& screen,
                                                          std::vector<std::string>* notes) {
    const auto note = [&](std::string text) {
        if (notes != nullptr) notes->push_back(std::move(text));
    };
    const std::size_t n_out = outputs.size();
    const std::size_t n_proj = screen.projectors.size();
    std::vector<std::optional<std::size_t>> result(n_out);
    std::vector<bool> used(n_proj, false);
    for (std::size_t i = 0; i < n_out && i < n_proj; ++i) {
        if (outputs[i].size == screen.projectors[i].output) {
            result[i] = i;
            used[i] = true;
        }
    }
    for (std::size_t i = 0; i < n_out; ++i) {
        if (result[i]) continue;
        for (std::size_t p = 0; p < n_proj; ++p) {
            if (!used[p] && screen.projectors[p].output == outputs[i].size) {
                result[i] = p;
                used[p] = true;
                break;
            }
        }
    }
    for (std::size_t i = 0; i < n_out; ++i) {
        if (result[i]) continue;
        for (std::size_t p = 0; p < n_proj; ++p) {
            if (used[p]) continue;
            result[i] = p;
            used[p] = true;
            const auto& proj = screen.projectors[p];
            note(
                fmt::format("output {} ({}x{}) shows projector '{}' calibrated for {}x{}: resampled to the output size",
                            outputs[i].name, outputs[i].size.width, outputs[i].size.height, proj.id, proj.output.width,
                            proj.output.height));
            break;
        }
        if (!result[i])
            note(fmt::format("output {} has no projector calibration left: it stays black", outputs[i].name));
    }
    for (std::size_t p = 0; p < n_proj; ++p) {
        if (!used[p])
            note(fmt::format("projector '{}' has no output: its part of the screen stays dark",
                             screen.projectors[p].id));
    }
    return result;
}

}  // namespace mogao
