// SPDX-License-Identifier: Apache-2.0
// What the appliance asks the farm to render: the viewer's pose in the virtual world, the camera
// model (pinhole or the cylindrical projection screen), the output size and the quality knobs.
//
// World frame: right-handed, metres, +y up. A yaw of 0 looks along -z; positive yaw turns left
// (counter-clockwise seen from above, i.e. a rotation about +y). Positive pitch looks up.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <variant>

#include <Eigen/Core>

#include "pixel_rect.h"

namespace mogao {

// Where the viewer's eye is and where it looks, in world coordinates (metres, degrees).
struct ViewerPose {
    Eigen::Vector3d eye{0.0, 1.6, 0.0};  // eye position, world metres
    double yaw_deg = 0.0;                // about +y, 0 = looking along -z
    double pitch_deg = 0.0;              // about the viewer's right axis, + = up
};

// A pinhole camera looking along the pose's forward direction.
struct PinholeCamera {
    double vertical_fov_deg = 60.0;  // full vertical field of view
};

// The cylindrical projection screen of the appliance (seed paper: a cylindrical screen lit by
// several projectors). The screen frame is physical: origin on the cylinder axis at floor level,
// +y up along the axis, -z toward the middle of the arc. The screen spans `arc_deg` of angle
// centred on -z, and heights [bottom_m, top_m]. The frame is the content of the screen:
// pixel column u maps to angle theta = -arc/2 + arc * (u + 0.5) / width measured from -z toward +x
// (left to right for a viewer inside the cylinder), row v maps to height
// top_m - (top_m - bottom_m) * (v + 0.5) / height. Each pixel's ray starts at the viewer's physical
// eye and passes through that screen point; the physical frame is then placed in the world by the
// ViewerPose (its eye is the physical eye, its yaw/pitch rotate the screen frame).
struct CylinderScreen {
    double radius_m = 3.0;
    double arc_deg = 180.0;  // (0, 360]
    double bottom_m = 0.0;
    double top_m = 2.5;
    Eigen::Vector3d eye_m{0.0, 1.6, 0.0};  // viewer's eye in the screen frame
};

using CameraModel = std::variant<PinholeCamera, CylinderScreen>;

// Quality knobs: every one trades time for error (see docs/benchmarks.md).
struct Quality {
    int spp = 1;                    // samples per pixel (Owen-scrambled Sobol' points in the pixel, 1 included)
    int max_bounces = 0;            // indirect bounces of the path tracer; 0 = direct light only
    int ao_samples = 0;             // cosine-weighted occlusion rays for the environment light; 0 traces 1
    int area_light_samples = 1;     // shadow rays per area light per sample
    double resolution_scale = 1.0;  // render at width*scale x height*scale, (0, 1]
    int jpeg_quality = 85;          // 1..100, TurboJPEG
};

struct ViewRequest {
    std::uint64_t frame_id = 0;
    ViewerPose pose;
    CameraModel camera = PinholeCamera{};
    ImageSize size{1920, 1080};
    Quality quality;
    std::uint64_t seed = 1;            // same seed + same request = same pixels
    std::int64_t request_time_ns = 0;  // CLOCK_REALTIME of the sender, for latency accounting
    // Farm-internal, never on the link's wire: the link server's id of the session that sent the
    // request (0 = none), so the farm keeps per-session state (cost map, accumulation, frame time).
    std::uint64_t session = 0;
    // Farm-internal, never on the link's wire: trace this frame with the renderer's radiance cache
    // (renderfarm/trace/radiance_cache.h: a biased, much cheaper estimate for moving views).
    bool radiance_cache = false;
    // Farm-internal, never on the link's wire: the scene time of the frame, seconds (>= 0, finite),
    // at which animated lights are evaluated (renderfarm/scene/scene.h, LightAnimation). The farm's
    // admin stamps it; 0 for path tours.
    double scene_time_s = 0.0;
    // Farm-internal, never on the link's wire: a cached frame (radiance_cache) shades only one pixel
    // in `shading_one_in` (the pixels (x, y) with (x + k·y + shading_phase) mod N = 0, N =
    // shading_one_in, k = ⌈N/2⌉, so every N consecutive phases shade every pixel once) and the
    // cache's training pixels; every other surface pixel gets its primary hit's guides and the
    // radiance kUnshadedRadiance, for the admin to take from the reprojected history
    // (renderfarm/denoise/temporal_accumulation.h). 1 shades every pixel.
    int shading_one_in = 1;  // [1, 16]
    int shading_phase = 0;   // [0, shading_one_in)
};

// The red channel of a pixel a sparse cached frame did not shade (ViewRequest::shading_one_in): no
// radiance is negative.
inline constexpr float kUnshadedRadiance = -1.0f;

// Whether a frame with `one_in` and `phase` (ViewRequest::shading_one_in, shading_phase) shades
// pixel (x, y) of its render size.
[[nodiscard]] inline bool shades_pixel(int one_in, int phase, int x, int y) {
    const int k = (one_in + 1) / 2;
    return (x + k * y + phase) % one_in == 0;
}

// The size actually traced: size scaled by quality.resolution_scale, rounded to nearest, at least
// 1x1. The farm and the renderer both use this one definition.
[[nodiscard]] inline ImageSize render_size(const ViewRequest& view) {
    const auto scaled = [&](int n) {
        return std::max(1, static_cast<int>(std::lround(n * view.quality.resolution_scale)));
    };
    return {scaled(view.size.width), scaled(view.size.height)};
}

}  // namespace mogao
