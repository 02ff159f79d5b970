// SPDX-License-Identifier: Apache-2.0
// The farm's view policy: which views of the models an authenticated appliance may have.
//
// Museums may not copy the precious models, and a certificate holder could otherwise harvest views
// no visitor would ever see: from inside a statue, from above the room, through a 1-degree pinhole
// zoomed onto one detail at full resolution. The policy moves each request into what the museum's
// tour can show, and never refuses it (the appliance still gets a frame):
//  - eye: moved to the nearest point of the scene's visitable area (common/viewer.h, the scene
//    file's "viewer.visitable": floor rectangle in x/z and eye-height range), when the scene has
//    one and `visitable_area` is on;
//  - camera, when `screen` is set (the appliances' cylindrical screen): a cylinder request gets the
//    screen's radius, heights and eye, and at most the screen's arc plus `max_guard_deg` on each
//    side (the late rotational warp's guard band, kiosk [screen].guard_deg); a pinhole request is
//    answered with the screen's camera (same size);
//  - pinhole field of view: widened to `min_fov_deg` when narrower (a zoom onto a detail), when no
//    screen is set;
//  - resolution, when `max_size` is set (the appliance's content resolution): a request whose
//    rendered size (render_size) is wider or taller is rendered at a lower resolution_scale, so that
//    it fits; the frame's nominal size is kept (the appliance scales it up).
// A farm serving several museums holds one policy per appliance certificate (view_policy_file.h).
// The pixel and ray bounds of request_policy.h apply after this.
//
// Units: metres, degrees. Errors: ViewPolicy::validate throws std::invalid_argument naming the field
// and its limit.
#pragma once

#include <optional>
#include <string>

#include "common/view_request.h"
#include "common/viewer.h"

namespace mogao {

struct ViewPolicy {
    bool visitable_area = true;            // keep the eye in the scene's visitable area, if it has one
    std::optional<CylinderScreen> screen;  // the appliances' screen; none: any camera
    double max_guard_deg = 30.0;           // extra arc allowed on each side of the screen's, [0, 180)
    double min_fov_deg = 0.0;              // pinhole requests below are widened to it, [0, 179]; 0 = off
    std::optional<ImageSize> max_size;     // rendered pixels at most, each side in [16, 16384]; none: any
    void validate() const;
};

struct ViewDecision {
    ViewRequest view;     // the request as it will be rendered
    std::string changes;  // e.g. "eye (9, 1.6, 0) -> (4, 1.6, 0), camera pinhole -> screen" (empty: unchanged)
};

// Applies `policy` to a validated request for a scene whose visitor is `viewer`.
[[nodiscard]] ViewDecision apply_view_policy(const ViewRequest& request, const Viewer& viewer,
                                             const ViewPolicy& policy);

}  // namespace mogao
