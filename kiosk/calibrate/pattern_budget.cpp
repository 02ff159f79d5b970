// SPDX-License-Identifier: Apache-2.0
// Captured image count and capture time of the on-site calibration (pattern_budget.h).
#include "kiosk/calibrate/pattern_budget.h"

#include <algorithm>

namespace mogao::calibrate {

PatternBudget pattern_budget(const autocal::CalibrationPrior& prior, bool colour,
                             const autocal::ColourOptions& colour_options, const autocal::AutocalOptions& options,
                             const autocal::SelfCheckOptions& self_check, bool lossy_frames) {
    const int n = static_cast<int>(prior.projectors.size());
    const auto bits = [&](int extent) {
        const int all = autocal::gray_code_bits(extent);
        return options.max_gray_bits > 0 ? std::min(all, options.max_gray_bits) : all;
    };
    PatternBudget b;
    b.identification = 2 + n;
    b.geometry = 2 + 2 * n;
    for (const autocal::DeviceModel& p : prior.projectors) {
        b.geometry += 2 + 2 * (bits(p.resolution.width) + bits(p.resolution.height)) + 2 * options.phase_shifts;
    }
    b.geometry *= options.frames_per_pattern;
    b.geometry += 4;  // the camera timing's single frames (camera_timing.h)
    if (colour) {
        const int steps = colour_options.ramp_steps;
        int low = 2;
        for (int i = 1; i < steps; ++i) {
            const double s = static_cast<double>(i) / (steps - 1);
            if (s <= 0.25 && s != 1.0 / 32.0 && s != 1.0 / 16.0) ++low;
        }
        // Each image's count (colour_calibration.h, exposure dither): `raw` frames, with lossy frames at least the
        // dither's.
        const bool dither = lossy_frames && colour_options.dither_frames > 1 && colour_options.dither_span > 0.0;
        const auto frames = [&](int raw, int dithered) { return dither ? std::max(raw, dithered) : raw; };
        const int d = colour_options.dither_frames;
        const int bounce = colour_options.lens_falloff && colour_options.screen_bounce ? n : 0;
        b.colour = frames(1, d) + frames(4, d) + bounce * frames(1, d) +
                   n * 3 * ((steps - 2 + low) * frames(1, d) + frames(1, colour_options.full_level_frames)) +
                   frames(colour_options.dark_frames, d);
    }
    b.self_check = self_check.frames * (2 + 3 * n);
    return b;
}

double seconds_per_image(double fps, int settle_ms, int drop_frames) {
    return settle_ms / 1000.0 + (drop_frames + 1) / fps;
}

}  // namespace mogao::calibrate
