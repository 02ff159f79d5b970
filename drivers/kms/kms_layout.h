// SPDX-License-Identifier: Apache-2.0
// Pure decisions of KMS output setup, separate from the ioctls so they are unit-tested without a
// device: which mode a connector gets, which CRTC drives which connector, which plane scans out.
#pragma once

#include <xf86drmMode.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace mogao {

// The mode a projector output uses: a mode forced on the kernel command line
// (`video=<connector>:<W>x<H>[@<Hz>]`, which the kernel adds as DRM_MODE_TYPE_USERDEF; see the
// kernel's Documentation/fb/modedb.rst), else the connector's preferred mode
// (DRM_MODE_TYPE_PREFERRED, the projector's native panel), else the largest area, then the
// highest refresh. nullopt for no modes.
[[nodiscard]] std::optional<std::size_t> pick_mode(std::span<const drmModeModeInfo> modes);

// Vertical refresh in Hz from the pixel clock and totals (more precise than mode.vrefresh,
// e.g. 59.94 rather than 60); 0 when the totals are 0.
[[nodiscard]] double refresh_hz(const drmModeModeInfo& mode);

// Gives each connector a distinct CRTC index (bit i of crtc_masks[c] = CRTC i can drive connector
// c, the union of its encoders' possible_crtcs), maximising the number of lit connectors
// (bipartite matching, so an earlier connector never takes the only CRTC a later one could use).
// Result[c] = CRTC index, or nullopt when connector c cannot get one.
[[nodiscard]] std::vector<std::optional<int>> assign_crtcs(std::span<const std::uint32_t> crtc_masks, int crtc_count);

struct PlaneCandidate {
    std::uint32_t id = 0;
    std::uint32_t possible_crtcs = 0;  // bit i = CRTC index i
    std::uint64_t type = 0;            // DRM_PLANE_TYPE_PRIMARY / OVERLAY / CURSOR
    bool supports_format = false;      // scans out the framebuffer format we render (XRGB8888)
};

// The plane for CRTC `crtc_index`: a primary plane if one fits, else an overlay; never a cursor
// plane, never one in `taken` (taken[i] refers to planes[i]; may be shorter than planes).
[[nodiscard]] std::optional<std::size_t> pick_plane(std::span<const PlaneCandidate> planes, int crtc_index,
                                                    const std::vector<bool>& taken);

}  // namespace mogao
