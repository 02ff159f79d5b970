// SPDX-License-Identifier: Apache-2.0
// The sparse random-dot pattern of the content-independent fallback (fallback_pattern.h).
#include "appliance/selfcal/fallback_pattern.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

namespace mogao::selfcal {

void check_pattern_options(const PatternOptions& o) {
    const auto fail = [](const std::string& what) { throw std::invalid_argument("PatternOptions: " + what); };
    if (!(o.amplitude > 0.0 && o.amplitude <= 0.2)) fail("amplitude in (0, 0.2]");
    if (o.cell_px < 6) fail("cell_px >= 6");
    if (!(o.recheck_s > 0.0) || !std::isfinite(o.recheck_s)) fail("recheck_s > 0");
}

cv::Mat1f fallback_pattern(cv::Size size, const PatternOptions& o) {
    check_pattern_options(o);
    if (size.width < 16 || size.height < 16) throw std::invalid_argument("fallback_pattern: size under 16x16");
    // The cell scales with the frame so the pattern looks the same at any content size.
    const double scale = size.width / 960.0;
    const int cell = std::max(6, static_cast<int>(std::lround(o.cell_px * scale)));
    cv::Mat1f p(size, 0.0f);
    cv::RNG rng(o.seed);
    for (int y = cell / 2; y < size.height; y += cell) {
        for (int x = cell / 2; x < size.width; x += cell) {
            const cv::Point c(x + rng.uniform(-cell / 3, cell / 3 + 1), y + rng.uniform(-cell / 3, cell / 3 + 1));
            const double r = scale * rng.uniform(3.5, 7.0);  // about 1.5 to 3 camera pixels at half resolution
            const auto v = static_cast<float>(rng.uniform(0.5, 1.0));
            cv::circle(p, c, std::max(1, static_cast<int>(std::lround(r))), v, cv::FILLED, cv::LINE_AA);
        }
    }
    return p;
}

}  // namespace mogao::selfcal
