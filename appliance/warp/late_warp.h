// SPDX-License-Identifier: Apache-2.0
// Late rotational warp for the cylindrical screen (common/view_request.h, CylinderScreen): the farm
// renders a guard band beyond the screen's arc, and at each display refresh the kiosk shifts the
// content by the yaw the navigation accumulated since the frame's request, so a turn shows up on
// the wall within one display round whatever the farm's latency (the rotational part of
// "time warp" / asynchronous reprojection: Mark, McMillan and Bishop, "Post-Rendering 3D Warping",
// I3D 1997; van Waveren, "The Asynchronous Time Warp for Virtual Reality on Consumer Hardware",
// VRST 2016).
//
// Frames and units. Screen angle theta (degrees) is measured from the screen's -z toward +x, i.e.
// left to right for a viewer inside the cylinder; content column u (pixels, centre at u + 0.5)
// maps to theta = -arc/2 + arc * (u + 0.5) / width. Yaw (degrees) is the ViewerPose's: positive
// turns left (counter-clockwise seen from above).
//
// Why a shift is exact. With the eye on the cylinder's axis, the ray through screen angle theta has
// world azimuth theta - yaw (both measured the same way), whatever the pixel's row. A frame
// rendered at yaw y0 shows azimuth a at theta' = a + y0; at display yaw y1 the screen angle theta
// must show azimuth theta - y1, which the frame holds at theta' = theta - (y1 - y0). So the content
// moves by delta = y1 - y0 degrees to the right (a left turn moves the world right), i.e. by
// delta / arc * width pixels: a horizontal shift, the same for every row.
//
// Normalised content coordinates. The projector calibration's warp maps give content coordinates
// s in [0, 1] across the screen's arc. The guarded frame spans arc_g = arc + 2 g degrees; screen
// coordinate s is fetched at s' = s * arc / arc_g + (g - delta) / arc_g of the guarded frame
// (ContentShift: scale and offset of that affine map, applied by the warp-and-blend shader,
// drivers/egl/warp_blend_renderer.h).
//
// At the band's edge: delta is clamped to [-g, +g], so the screen never samples outside what was
// rendered; a turn beyond the band shows its shift up to g at once and the rest when the next
// frame arrives (`clamped` says so).
//
// Limits, not corrected: translation (walking changes parallax, which a shift cannot show; the
// frame keeps the request's eye position until the next frame), pitch and roll (not a column
// shift), and an eye off the cylinder's axis (then the ray azimuth is not theta - yaw: a yaw is no
// longer a pure shift; the error grows with the eye's distance from the axis over the radius).
#pragma once

#include "common/pixel_rect.h"
#include "common/result.h"
#include "common/view_request.h"

namespace mogao {

// The request a guard band turns the screen's camera into.
struct GuardedScreen {
    CylinderScreen camera;  // arc_deg widened to arc + 2 * guard_deg (the rest unchanged)
    ImageSize size;         // width + 2 * guard_px, the same height: the same degrees per column
    int guard_px = 0;       // columns of band on each side
    double guard_deg = 0;   // the band actually rendered each side: guard_px * arc / width
};

// `guard_deg` of band each side of `screen` for content of `content` pixels: the band is rounded to
// whole columns so that the screen's columns stay on the frame's column grid. EINVAL (naming the
// field) when guard_deg is negative or not finite, the screen's arc is not in (0, 360], the width
// is < 1, or the widened arc would exceed 360 degrees. guard_deg = 0 returns the screen unchanged.
[[nodiscard]] Result<GuardedScreen> guard_band(const CylinderScreen& screen, ImageSize content, double guard_deg);

// The affine map s' = s * scale + offset from screen content coordinates to the guarded frame's.
struct ContentShift {
    double scale = 1.0;
    double offset = 0.0;
    double shift_deg = 0.0;  // the shift applied: delta clamped to [-guard, +guard]
    bool clamped = false;    // |delta| exceeded the band
};

// The late warp for a frame of `screen_arc_deg` + 2 * `guard_deg` degrees shown `yaw_delta_deg`
// (display-time yaw minus the frame's request yaw; positive = turned left since) later. A
// non-finite delta is treated as 0 (the frame is shown unshifted).
[[nodiscard]] ContentShift late_rotational_shift(double screen_arc_deg, double guard_deg, double yaw_delta_deg);

}  // namespace mogao
