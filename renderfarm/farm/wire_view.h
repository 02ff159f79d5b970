// SPDX-License-Identifier: Apache-2.0
// The view request as it travels between MPI ranks of one farm: a trivially copyable struct sent
// as MPI_BYTE. All ranks run the same binary on the same architecture (a farm is homogeneous), so
// no byte-order or padding conversion is needed; the appliance link uses its own versioned schema.
#pragma once

#include <cstdint>
#include <type_traits>

#include "common/view_request.h"

namespace mogao {

struct WireView {
    std::uint64_t frame_id, seed;
    std::int64_t request_time_ns;
    double eye[3], yaw_deg, pitch_deg;
    std::int32_t camera_kind;  // 0 pinhole, 1 cylinder
    double fov_deg, radius_m, arc_deg, bottom_m, top_m, screen_eye[3];
    std::int32_t width, height, spp, max_bounces, ao_samples, area_light_samples, jpeg_quality;
    double resolution_scale;
    std::int32_t stop;       // 1: no more frames, render ranks leave their loop
    std::int32_t linear;     // 0: sRGB8, 1: linear radiance (PackedPixels::linear), 2: and guides (::linear_guided)
    std::uint64_t sequence;  // the dispatcher's count of frames sent: names the frame in progress reports and cuts
    std::int32_t radiance_cache;                 // ViewRequest::radiance_cache
    double scene_time_s;                         // ViewRequest::scene_time_s
    std::int32_t shading_one_in, shading_phase;  // ViewRequest's
};
static_assert(std::is_trivially_copyable_v<WireView>);

inline WireView to_wire(const ViewRequest& v) {
    WireView w{};
    w.frame_id = v.frame_id;
    w.seed = v.seed;
    w.request_time_ns = v.request_time_ns;
    for (int i = 0; i < 3; ++i) w.eye[i] = v.pose.eye[i];
    w.yaw_deg = v.pose.yaw_deg;
    w.pitch_deg = v.pose.pitch_deg;
    if (const auto* pin = std::get_if<PinholeCamera>(&v.camera)) {
        w.camera_kind = 0;
        w.fov_deg = pin->vertical_fov_deg;
    } else {
        const auto& cyl = std::get<CylinderScreen>(v.camera);
        w.camera_kind = 1;
        w.radius_m = cyl.radius_m;
        w.arc_deg = cyl.arc_deg;
        w.bottom_m = cyl.bottom_m;
        w.top_m = cyl.top_m;
        for (int i = 0; i < 3; ++i) w.screen_eye[i] = cyl.eye_m[i];
    }
    w.width = v.size.width;
    w.height = v.size.height;
    w.spp = v.quality.spp;
    w.max_bounces = v.quality.max_bounces;
    w.ao_samples = v.quality.ao_samples;
    w.area_light_samples = v.quality.area_light_samples;
    w.jpeg_quality = v.quality.jpeg_quality;
    w.resolution_scale = v.quality.resolution_scale;
    w.radiance_cache = v.radiance_cache ? 1 : 0;
    w.scene_time_s = v.scene_time_s;
    w.shading_one_in = v.shading_one_in;
    w.shading_phase = v.shading_phase;
    return w;
}

inline ViewRequest from_wire(const WireView& w) {
    ViewRequest v;
    v.frame_id = w.frame_id;
    v.seed = w.seed;
    v.request_time_ns = w.request_time_ns;
    v.pose.eye = {w.eye[0], w.eye[1], w.eye[2]};
    v.pose.yaw_deg = w.yaw_deg;
    v.pose.pitch_deg = w.pitch_deg;
    if (w.camera_kind == 0) {
        v.camera = PinholeCamera{w.fov_deg};
    } else {
        v.camera = CylinderScreen{w.radius_m, w.arc_deg, w.bottom_m, w.top_m,
                                  Eigen::Vector3d(w.screen_eye[0], w.screen_eye[1], w.screen_eye[2])};
    }
    v.size = {w.width, w.height};
    v.quality = {w.spp, w.max_bounces, w.ao_samples, w.area_light_samples, w.resolution_scale, w.jpeg_quality};
    v.radiance_cache = w.radiance_cache != 0;
    v.scene_time_s = w.scene_time_s;
    v.shading_one_in = w.shading_one_in;
    v.shading_phase = w.shading_phase;
    return v;
}

}  // namespace mogao
