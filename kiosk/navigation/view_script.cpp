// SPDX-License-Identifier: Apache-2.0
#include "kiosk/navigation/view_script.h"

#include <stdexcept>

#include "common/camera_path.h"

namespace mogao {

ViewRequest make_view_template(const CylinderScreen& screen, const QualityConfig& quality) {
    ViewRequest r;
    r.camera = screen;
    r.size = quality.content;
    r.quality.spp = quality.spp;
    r.quality.jpeg_quality = quality.jpeg_quality;
    r.quality.max_bounces = quality.max_bounces;
    r.quality.ao_samples = quality.ao_samples;
    r.quality.area_light_samples = quality.area_light_samples;
    r.quality.resolution_scale = 1.0;
    r.request_time_ns = 0;
    return r;
}

ViewScript::ViewScript(std::vector<ViewerPose> poses, ViewRequest request_template)
    : poses_(std::move(poses)), template_(std::move(request_template)) {
    if (poses_.empty()) throw std::invalid_argument("ViewScript: no poses");
}

ViewRequest ViewScript::next() {
    ViewRequest r = template_;
    r.pose = poses_[next_];
    next_ = (next_ + 1) % poses_.size();
    r.request_time_ns = 0;
    return r;
}

ViewScript make_view_script(const NavigationConfig& navigation, ViewRequest request_template) {
    Viewer viewer;
    viewer.eye_height_m = navigation.eye_height_m;
    viewer.start = navigation.start;
    viewer.start_yaw_deg = navigation.start_yaw_deg;
    return ViewScript(make_camera_path(navigation.path, viewer, navigation.path_frames), std::move(request_template));
}

}  // namespace mogao
