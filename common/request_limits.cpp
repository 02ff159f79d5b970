// SPDX-License-Identifier: Apache-2.0
#include "common/request_limits.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <variant>

namespace mogao {
namespace {

[[noreturn]] void fail(std::string_view field, double value, std::string_view limit) {
    std::ostringstream message;
    message << "ViewRequest." << field << " = " << value << " is outside " << limit;
    throw std::invalid_argument(message.str());
}

void require_int(std::string_view field, int value, IntRange range) {
    if (!range.contains(value)) fail(field, value, range.text());
}

void require_finite(std::string_view field, double value) {
    if (!std::isfinite(value)) fail(field, value, "the finite numbers");
}

}  // namespace

std::string IntRange::text() const {
    std::ostringstream out;
    out << '[' << min << ", " << max << ']';
    return out.str();
}

void validate_view_request(const ViewRequest& request) {
    namespace limits = request_limits;
    require_int("size.width", request.size.width, limits::kImageSide);
    require_int("size.height", request.size.height, limits::kImageSide);
    const Quality& q = request.quality;
    if (!(q.resolution_scale > 0.0 && q.resolution_scale <= 1.0)) {
        fail("quality.resolution_scale", q.resolution_scale, "(0, 1]");
    }
    require_int("quality.spp", q.spp, limits::kSpp);
    require_int("quality.max_bounces", q.max_bounces, limits::kMaxBounces);
    require_int("quality.ao_samples", q.ao_samples, limits::kAoSamples);
    require_int("quality.area_light_samples", q.area_light_samples, limits::kAreaLightSamples);
    require_int("quality.jpeg_quality", q.jpeg_quality, limits::kJpegQuality);
    require_finite("pose.eye.x", request.pose.eye.x());
    require_finite("pose.eye.y", request.pose.eye.y());
    require_finite("pose.eye.z", request.pose.eye.z());
    require_finite("pose.yaw_deg", request.pose.yaw_deg);
    require_finite("pose.pitch_deg", request.pose.pitch_deg);
    if (!(request.scene_time_s >= 0.0) || !std::isfinite(request.scene_time_s)) {
        fail("scene_time_s", request.scene_time_s, "[0, inf)");
    }
    require_int("shading_one_in", request.shading_one_in, limits::kShadingOneIn);
    require_int("shading_phase", request.shading_phase, IntRange{0, request.shading_one_in - 1});
    if (const auto* pinhole = std::get_if<PinholeCamera>(&request.camera)) {
        if (!(pinhole->vertical_fov_deg > 0.0 && pinhole->vertical_fov_deg < 180.0)) {
            fail("camera.vertical_fov_deg", pinhole->vertical_fov_deg, "(0, 180)");
        }
    } else {
        const auto& screen = std::get<CylinderScreen>(request.camera);
        if (!(screen.radius_m > 0.0) || !std::isfinite(screen.radius_m)) {
            fail("camera.radius_m", screen.radius_m, "(0, inf)");
        }
        if (!(screen.arc_deg > 0.0 && screen.arc_deg <= 360.0)) fail("camera.arc_deg", screen.arc_deg, "(0, 360]");
        require_finite("camera.bottom_m", screen.bottom_m);
        require_finite("camera.top_m", screen.top_m);
        if (!(screen.top_m > screen.bottom_m)) fail("camera.top_m", screen.top_m, "(bottom_m, inf)");
        require_finite("camera.eye_m.x", screen.eye_m.x());
        require_finite("camera.eye_m.y", screen.eye_m.y());
        require_finite("camera.eye_m.z", screen.eye_m.z());
    }
}

ImageSize render_size_for(const ViewRequest& request) {
    validate_view_request(request);
    const double scale = request.quality.resolution_scale;
    const auto scaled = [scale](int side) {
        return std::max(1, static_cast<int>(std::lround(static_cast<double>(side) * scale)));
    };
    return {scaled(request.size.width), scaled(request.size.height)};
}

}  // namespace mogao
