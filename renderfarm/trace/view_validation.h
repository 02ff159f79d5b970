// Checks a ViewRequest before rendering and computes the render size.
//
// Limits (inclusive unless noted): size.width/height in [1, 16384]; resolution_scale in (0, 1];
// spp in [1, 4096]; max_bounces in [0, 64]; ao_samples in [0, 1024]; area_light_samples in
// [1, 1024]; pose eye/yaw/pitch finite; pinhole vertical_fov_deg in (0, 180);
// cylinder radius_m > 0, arc_deg in (0, 360], top_m > bottom_m, all finite (eye_m too).
// Violations throw std::invalid_argument whose message names the field, its value and the limit,
// e.g. "ViewRequest.quality.spp = 0 is outside [1, 4096]".
#pragma once

#include "renderfarm/view/pixel_rect.h"
#include "renderfarm/view/view_request.h"

namespace mogao {

void validate_view_request(const ViewRequest& request);

// round(size * resolution_scale) per axis, at least 1 pixel. Validates the request first.
[[nodiscard]] ImageSize render_size_for(const ViewRequest& request);

}  // namespace mogao
