// SPDX-License-Identifier: Apache-2.0
#include "drivers/kms/kms_layout.h"

#include <algorithm>
#include <functional>

namespace mogao {

std::optional<std::size_t> pick_mode(std::span<const drmModeModeInfo> modes) {
    std::optional<std::size_t> best;
    const auto better = [&](const drmModeModeInfo& a, const drmModeModeInfo& b) {
        const bool ua = (a.type & DRM_MODE_TYPE_USERDEF) != 0;
        const bool ub = (b.type & DRM_MODE_TYPE_USERDEF) != 0;
        if (ua != ub) return ua;
        const bool pa = (a.type & DRM_MODE_TYPE_PREFERRED) != 0;
        const bool pb = (b.type & DRM_MODE_TYPE_PREFERRED) != 0;
        if (pa != pb) return pa;
        const long area_a = long{a.hdisplay} * a.vdisplay;
        const long area_b = long{b.hdisplay} * b.vdisplay;
        if (area_a != area_b) return area_a > area_b;
        return refresh_hz(a) > refresh_hz(b);
    };
    for (std::size_t i = 0; i < modes.size(); ++i) {
        if (!best || better(modes[i], modes[*best])) best = i;
    }
    return best;
}

double refresh_hz(const drmModeModeInfo& mode) {
    if (mode.htotal == 0 || mode.vtotal == 0) return 0.0;
    double hz = mode.clock * 1000.0 / (static_cast<double>(mode.htotal) * mode.vtotal);
    if ((mode.flags & DRM_MODE_FLAG_INTERLACE) != 0) hz *= 2.0;
    if ((mode.flags & DRM_MODE_FLAG_DBLSCAN) != 0) hz /= 2.0;
    if (mode.vscan > 1) hz /= mode.vscan;
    return hz;
}

std::vector<std::optional<int>> assign_crtcs(std::span<const std::uint32_t> crtc_masks, int crtc_count) {
    const int n = std::min(crtc_count, 32);
    std::vector<int> owner(static_cast<std::size_t>(std::max(n, 0)), -1);  // CRTC -> connector
    // Kuhn's augmenting paths; a handful of connectors and CRTCs, so the simple form is enough.
    std::function<bool(std::size_t, std::vector<bool>&)> try_assign = [&](std::size_t c, std::vector<bool>& seen) {
        for (int k = 0; k < n; ++k) {
            const auto ku = static_cast<std::size_t>(k);
            if ((crtc_masks[c] & (1u << k)) == 0 || seen[ku]) continue;
            seen[ku] = true;
            if (owner[ku] < 0 || try_assign(static_cast<std::size_t>(owner[ku]), seen)) {
                owner[ku] = static_cast<int>(c);
                return true;
            }
        }
        return false;
    };
    for (std::size_t c = 0; c < crtc_masks.size(); ++c) {
        std::vector<bool> seen(owner.size(), false);
        try_assign(c, seen);
    }
    std::vector<std::optional<int>> result(crtc_masks.size());
    for (std::size_t k = 0; k < owner.size(); ++k) {
        if (owner[k] >= 0) result[static_cast<std::size_t>(owner[k])] = static_cast<int>(k);
    }
    return result;
}

std::optional<std::size_t> pick_plane(std::span<const PlaneCandidate> planes, int crtc_index,
                                      const std::vector<bool>& taken) {
    if (crtc_index < 0 || crtc_index >= 32) return std::nullopt;
    std::optional<std::size_t> overlay;
    for (std::size_t i = 0; i < planes.size(); ++i) {
        const PlaneCandidate& p = planes[i];
        if ((i < taken.size() && taken[i]) || !p.supports_format || (p.possible_crtcs & (1u << crtc_index)) == 0) {
            continue;
        }
        if (p.type == DRM_PLANE_TYPE_PRIMARY) return i;
        if (p.type == DRM_PLANE_TYPE_OVERLAY && !overlay) overlay = i;
    }
    return overlay;
}

}  // namespace mogao
