// SPDX-License-Identifier: Apache-2.0
#include "appliance/autocal/colour_report.h"

#include <algorithm>

namespace mogao::autocal {

nlohmann::json colour_report(const ColourResult& c) {
    nlohmann::json out = {{"captures", c.captures}, {"matched_white", c.matched_white}, {"black_floor", c.black_floor},
                          {"ambient", c.ambient},   {"alpha_scale", c.alpha_scale},     {"white_floor", c.white_floor}};
    // The camera's vignetting as measured (camera_vignetting.h): V = 1 - a rho^2 - b rho^4, V at rho = 1.
    out["camera_vignetting"] = {{"measured", c.vignetting.measured},
                                {"a", c.vignetting.a},
                                {"b", c.vignetting.b},
                                {"at_rho_1", c.vignetting.corner},
                                {"at_rho_1_sigma", c.vignetting.corner_sigma},
                                {"projector_falloff", c.vignetting.projector_falloff},
                                {"samples", c.vignetting.samples},
                                {"fit_rms", c.vignetting.rms}};
    // A gain screen's half-gain angle as the colour step used it (estimated from the images, or the data sheet's).
    out["screen_half_gain_angle"] = {{"degrees", c.half_gain_angle_deg},
                                     {"estimated", c.half_gain_angle_estimated},
                                     {"fit_rms_at_data_sheet", c.told_half_gain_rms},
                                     {"fit_rms_at_estimate", c.half_gain_rms}};
    // The screen's reflectance for its own light (step 0), fitted where no projector's direct light reaches.
    out["screen_bounce"] = {{"reflectance", c.screen_bounce_reflectance}, {"samples", c.screen_bounce_samples}};
    for (const ProjectorPhotometry& p : c.projectors) {
        nlohmann::json ch = nlohmann::json::array();
        for (const ChannelResponse& r : p.channels) {
            ch.push_back({{"amplitude", r.amplitude}, {"gamma", r.gamma}, {"gamma_fit_rms", r.gamma_rms}});
        }
        out["projectors"].push_back(
            {{"id", p.id}, {"black", p.black}, {"gain", p.gain}, {"falloff", p.falloff.c}, {"channels", ch}});
    }
    return out;
}

nlohmann::json indirect_light_report(const IndirectLight* indirect) {
    if (indirect == nullptr) return {{"compensated", false}};
    const RgbFloatImage white = indirect->flat_field(1.0);
    double most = 0.0, sum = 0.0;
    for (const float v : white.pixels) {
        most = std::max(most, static_cast<double>(v));
        sum += v;
    }
    return {{"compensated", true},
            {"patches", {indirect->columns(), indirect->rows()}},
            {"white_field_max", most},
            {"white_field_mean", white.pixels.empty() ? 0.0 : sum / static_cast<double>(white.pixels.size())}};
}

}  // namespace mogao::autocal
