// SPDX-License-Identifier: Apache-2.0
// The one table of view-request limits, and the check every ViewRequest goes through before it is
// rendered. The renderer's validation (below), the link's wire conversion, the kiosk's config
// reader and the programs' command lines all read these constants, so the kiosk can never accept
// what the farm refuses.
//
// Limits (inclusive unless noted): size.width/height in kImageSide (frames over the link: at least
// kLinkImageSide.min); resolution_scale in (0, 1]; spp, max_bounces, ao_samples,
// area_light_samples, jpeg_quality in their ranges below; pose eye/yaw/pitch finite; pinhole
// vertical_fov_deg in (0, 180); cylinder radius_m > 0, arc_deg in (0, 360], top_m > bottom_m, all
// finite (eye_m too); scene_time_s finite and >= 0.
// Errors: validate_view_request throws std::invalid_argument whose message names the field, its
// value and the limit, e.g. "ViewRequest.quality.spp = 0 is outside [1, 4096]".
#pragma once

#include <string>

#include "common/pixel_rect.h"
#include "common/view_request.h"

namespace mogao {

// An inclusive integer range [min, max].
struct IntRange {
    int min;
    int max;
    [[nodiscard]] constexpr bool contains(long long v) const { return v >= min && v <= max; }
    [[nodiscard]] std::string text() const;  // "[min, max]"
};

namespace request_limits {
// Pixels per side of a rendered frame. 16384 bounds a frame's float film at 3 GiB.
inline constexpr IntRange kImageSide{1, 16384};
// Pixels per side of a frame sent over the link: below 16 px a JPEG is all block edges.
inline constexpr IntRange kLinkImageSide{16, 16384};
inline constexpr IntRange kSpp{1, 4096};               // samples per pixel
inline constexpr IntRange kMaxBounces{0, 64};          // path-tracing bounces
inline constexpr IntRange kAoSamples{0, 1024};         // occlusion rays for the environment light
inline constexpr IntRange kAreaLightSamples{1, 1024};  // shadow rays per area light per sample
inline constexpr IntRange kJpegQuality{1, 100};        // TurboJPEG quality
inline constexpr IntRange kShadingOneIn{1, 16};        // a sparse cached frame shades 1 pixel in N
}  // namespace request_limits

void validate_view_request(const ViewRequest& request);

// round(size * resolution_scale) per axis, at least 1 pixel. Validates the request first.
[[nodiscard]] ImageSize render_size_for(const ViewRequest& request);

}  // namespace mogao
