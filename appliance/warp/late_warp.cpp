// SPDX-License-Identifier: Apache-2.0
#include "appliance/warp/late_warp.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace mogao {

Result<GuardedScreen> guard_band(const CylinderScreen& screen, ImageSize content, double guard_deg) {
    if (!std::isfinite(guard_deg) || guard_deg < 0) {
        return make_error(EINVAL, "guard_deg must be finite and >= 0, got " + std::to_string(guard_deg));
    }
    if (!(screen.arc_deg > 0 && screen.arc_deg <= 360)) {
        return make_error(EINVAL, "screen arc_deg must be in (0, 360], got " + std::to_string(screen.arc_deg));
    }
    if (content.width < 1 || content.height < 1) return make_error(EINVAL, "content size must be at least 1x1");
    if (screen.arc_deg + 2 * guard_deg > 360) {
        return make_error(EINVAL, "guard_deg " + std::to_string(guard_deg) + " widens the " +
                                      std::to_string(screen.arc_deg) + " degree arc beyond 360 (at most " +
                                      std::to_string((360 - screen.arc_deg) / 2) + ")");
    }
    GuardedScreen g{screen, content, 0, 0.0};
    const double deg_per_px = screen.arc_deg / content.width;
    g.guard_px = static_cast<int>(std::lround(guard_deg / deg_per_px));
    // Rounding up may pass 360 by less than a column: stay within it.
    while (g.guard_px > 0 && screen.arc_deg + 2 * g.guard_px * deg_per_px > 360 + 1e-9) --g.guard_px;
    g.guard_deg = g.guard_px * deg_per_px;
    g.size.width = content.width + 2 * g.guard_px;
    g.camera.arc_deg = screen.arc_deg * g.size.width / content.width;
    return g;
}

ContentShift late_rotational_shift(double screen_arc_deg, double guard_deg, double yaw_delta_deg) {
    ContentShift s;
    const double delta = std::isfinite(yaw_delta_deg) ? yaw_delta_deg : 0.0;
    const double guard = std::max(0.0, guard_deg);
    s.shift_deg = std::clamp(delta, -guard, guard);
    s.clamped = s.shift_deg != delta;
    const double guarded_arc = screen_arc_deg + 2 * guard;
    s.scale = screen_arc_deg / guarded_arc;
    s.offset = (guard - s.shift_deg) / guarded_arc;
    return s;
}

}  // namespace mogao
