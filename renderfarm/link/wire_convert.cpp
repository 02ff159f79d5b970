// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/link/wire_convert.h"

#include <cmath>
#include <cstdint>
#include <sstream>
#include <string_view>
#include <variant>

namespace mogao {
namespace {

namespace L = request_limits;

namespace v1 = link::v1;

std::string outside(std::string_view field, double value, std::string_view limit) {
    std::ostringstream message;
    message << field << " = " << value << " is outside " << limit;
    return message.str();
}

// int64 holds every uint32 and int, so a huge wire value is reported as sent, never wrapped.
std::string check_range(std::string_view field, std::int64_t value, int lo, int hi) {
    if (value < lo || value > hi) {
        std::ostringstream message;
        message << field << " = " << value << " is outside [" << lo << ", " << hi << ']';
        return message.str();
    }
    return {};
}

std::string check_finite(std::string_view field, double value) {
    return std::isfinite(value) ? std::string{} : outside(field, value, "the finite numbers");
}

std::string check_vec(std::string_view field, const Eigen::Vector3d& v) {
    const char* axes[] = {".x", ".y", ".z"};
    for (int i = 0; i < 3; ++i) {
        if (auto e = check_finite(std::string(field) + axes[i], v[i]); !e.empty()) return e;
    }
    return {};
}

Eigen::Vector3d vec_from(const v1::Vec3& v) { return {v.x(), v.y(), v.z()}; }

void vec_to(const Eigen::Vector3d& v, v1::Vec3& out) {
    out.set_x(v.x());
    out.set_y(v.y());
    out.set_z(v.z());
}

ViewerPose pose_from(const v1::PoseMsg& msg) {
    ViewerPose pose;
    pose.eye = vec_from(msg.eye_m());
    pose.yaw_deg = msg.yaw_deg();
    pose.pitch_deg = msg.pitch_deg();
    return pose;
}

std::string check_pose(const ViewerPose& pose) {
    if (auto e = check_vec("pose.eye_m", pose.eye); !e.empty()) return e;
    if (auto e = check_finite("pose.yaw_deg", pose.yaw_deg); !e.empty()) return e;
    return check_finite("pose.pitch_deg", pose.pitch_deg);
}

}  // namespace

std::string validate_link_request(const ViewRequest& r) {
    // The first failing check wins; the order follows the message's field order.
    if (r.frame_id == 0) return "request_id = 0 is reserved for acknowledgement-only messages";
    if (auto e = check_pose(r.pose); !e.empty()) return e;
    if (const auto* pinhole = std::get_if<PinholeCamera>(&r.camera)) {
        if (!(pinhole->vertical_fov_deg > 0.0 && pinhole->vertical_fov_deg < 180.0)) {
            return outside("pinhole.vertical_fov_deg", pinhole->vertical_fov_deg, "(0, 180)");
        }
    } else {
        const auto& c = std::get<CylinderScreen>(r.camera);
        if (!(c.radius_m > 0.0) || !std::isfinite(c.radius_m))
            return outside("cylinder.radius_m", c.radius_m, "(0, inf)");
        if (!(c.arc_deg > 0.0 && c.arc_deg <= 360.0)) return outside("cylinder.arc_deg", c.arc_deg, "(0, 360]");
        if (auto e = check_finite("cylinder.bottom_m", c.bottom_m); !e.empty()) return e;
        if (auto e = check_finite("cylinder.top_m", c.top_m); !e.empty()) return e;
        if (!(c.top_m > c.bottom_m)) return outside("cylinder.top_m", c.top_m, "(bottom_m, inf)");
        if (auto e = check_vec("cylinder.eye_m", c.eye_m); !e.empty()) return e;
    }
    if (auto e = check_range("width", r.size.width, kMinLinkImageSide, kMaxLinkImageSide); !e.empty()) return e;
    if (auto e = check_range("height", r.size.height, kMinLinkImageSide, kMaxLinkImageSide); !e.empty()) return e;
    const Quality& q = r.quality;
    if (auto e = check_range("quality.spp", q.spp, L::kSpp.min, L::kSpp.max); !e.empty()) return e;
    if (auto e = check_range("quality.max_bounces", q.max_bounces, L::kMaxBounces.min, L::kMaxBounces.max); !e.empty())
        return e;
    if (auto e = check_range("quality.ao_samples", q.ao_samples, L::kAoSamples.min, L::kAoSamples.max); !e.empty())
        return e;
    if (auto e = check_range("quality.area_light_samples", q.area_light_samples, L::kAreaLightSamples.min,
                             L::kAreaLightSamples.max);
        !e.empty())
        return e;
    if (!(q.resolution_scale > 0.0 && q.resolution_scale <= 1.0)) {
        return outside("quality.resolution_scale", q.resolution_scale, "(0, 1]");
    }
    return check_range("quality.jpeg_quality", q.jpeg_quality, L::kJpegQuality.min, L::kJpegQuality.max);
}

void pose_to_msg(const ViewerPose& pose, v1::PoseMsg& msg) {
    vec_to(pose.eye, *msg.mutable_eye_m());
    msg.set_yaw_deg(pose.yaw_deg);
    msg.set_pitch_deg(pose.pitch_deg);
}

void view_to_msg(const ViewRequest& r, v1::ViewRequestMsg& msg) {
    msg.set_request_id(r.frame_id);
    pose_to_msg(r.pose, *msg.mutable_pose());
    if (const auto* pinhole = std::get_if<PinholeCamera>(&r.camera)) {
        msg.mutable_pinhole()->set_vertical_fov_deg(pinhole->vertical_fov_deg);
    } else {
        const auto& c = std::get<CylinderScreen>(r.camera);
        auto& out = *msg.mutable_cylinder();
        out.set_radius_m(c.radius_m);
        out.set_arc_deg(c.arc_deg);
        out.set_bottom_m(c.bottom_m);
        out.set_top_m(c.top_m);
        vec_to(c.eye_m, *out.mutable_eye_m());
    }
    // Negative sizes or counts would wrap in uint32; send 0 instead so the farm refuses them by name.
    const auto u32 = [](int v) { return v < 0 ? 0u : static_cast<std::uint32_t>(v); };
    msg.set_width(u32(r.size.width));
    msg.set_height(u32(r.size.height));
    auto& q = *msg.mutable_quality();
    q.set_spp(u32(r.quality.spp));
    q.set_max_bounces(u32(r.quality.max_bounces));
    q.set_ao_samples(u32(r.quality.ao_samples));
    q.set_area_light_samples(u32(r.quality.area_light_samples));
    q.set_resolution_scale(r.quality.resolution_scale);
    q.set_jpeg_quality(u32(r.quality.jpeg_quality));
    msg.set_seed(r.seed);
    msg.set_request_time_ns(r.request_time_ns);
}

std::string view_from_msg(const v1::ViewRequestMsg& msg, ViewRequest& out) {
    if (msg.request_id() == 0) return "request_id = 0 is reserved for acknowledgement-only messages";
    if (!msg.has_pose()) return "pose is missing";
    if (!msg.pose().has_eye_m()) return "pose.eye_m is missing";
    if (!msg.has_quality()) return "quality is missing";
    // Check the unsigned fields before narrowing them to int.
    const auto& q = msg.quality();
    struct Field {
        std::string_view name;
        std::uint32_t value;
        int lo, hi;
    };
    const Field fields[] = {
        {"width", msg.width(), kMinLinkImageSide, kMaxLinkImageSide},
        {"height", msg.height(), kMinLinkImageSide, kMaxLinkImageSide},
        {"quality.spp", q.spp(), L::kSpp.min, L::kSpp.max},
        {"quality.max_bounces", q.max_bounces(), L::kMaxBounces.min, L::kMaxBounces.max},
        {"quality.ao_samples", q.ao_samples(), L::kAoSamples.min, L::kAoSamples.max},
        {"quality.area_light_samples", q.area_light_samples(), L::kAreaLightSamples.min, L::kAreaLightSamples.max},
        {"quality.jpeg_quality", q.jpeg_quality(), L::kJpegQuality.min, L::kJpegQuality.max}};
    for (const auto& f : fields) {
        if (auto e = check_range(f.name, f.value, f.lo, f.hi); !e.empty()) return e;
    }
    // Every field of `out` is assigned below (no `out = ViewRequest{}`: GCC 12 with sanitizers
    // then reports a false maybe-uninitialized in the variant's move).
    out.frame_id = msg.request_id();
    out.pose = pose_from(msg.pose());
    switch (msg.camera_case()) {
        case v1::ViewRequestMsg::kPinhole:
            out.camera.emplace<PinholeCamera>(PinholeCamera{msg.pinhole().vertical_fov_deg()});
            break;
        case v1::ViewRequestMsg::kCylinder: {
            const auto& c = msg.cylinder();
            if (!c.has_eye_m()) return "cylinder.eye_m is missing";
            out.camera.emplace<CylinderScreen>(
                CylinderScreen{c.radius_m(), c.arc_deg(), c.bottom_m(), c.top_m(), vec_from(c.eye_m())});
            break;
        }
        default:
            return "camera is missing (set pinhole or cylinder)";
    }
    out.size = {static_cast<int>(msg.width()), static_cast<int>(msg.height())};
    out.quality.spp = static_cast<int>(q.spp());
    out.quality.max_bounces = static_cast<int>(q.max_bounces());
    out.quality.ao_samples = static_cast<int>(q.ao_samples());
    out.quality.area_light_samples = static_cast<int>(q.area_light_samples());
    out.quality.resolution_scale = q.resolution_scale();
    out.quality.jpeg_quality = static_cast<int>(q.jpeg_quality());
    out.seed = msg.seed();
    out.request_time_ns = msg.request_time_ns();
    return validate_link_request(out);
}

std::string frame_from_msg(v1::FrameMsg& msg, LinkFrame& out) {
    if (msg.frame_id() == 0) return "frame_id = 0 is not a frame";
    if (!msg.has_pose() || !msg.pose().has_eye_m()) return "frame pose is missing";
    if (auto e = check_range("frame width", msg.width(), 1, kMaxLinkImageSide); !e.empty()) return e;
    if (auto e = check_range("frame height", msg.height(), 1, kMaxLinkImageSide); !e.empty()) return e;
    if (msg.jpeg().empty()) return "frame jpeg is empty";
    if (msg.jpeg().size() > kMaxFrameJpegBytes) {
        return "frame jpeg of " + std::to_string(msg.jpeg().size()) + " bytes is above the limit of " +
               std::to_string(kMaxFrameJpegBytes);
    }
    out.pose = pose_from(msg.pose());
    if (auto e = check_pose(out.pose); !e.empty()) return "frame " + e;
    out.frame_id = msg.frame_id();
    out.request_id = msg.request_id();
    out.size = {static_cast<int>(msg.width()), static_cast<int>(msg.height())};
    out.spp = msg.spp();
    out.bounces = msg.bounces();
    out.times.request_ns = msg.request_time_ns();
    out.times.received_ns = msg.received_ns();
    out.times.render_start_ns = msg.render_start_ns();
    out.times.render_end_ns = msg.render_end_ns();
    out.times.encode_end_ns = msg.encode_end_ns();
    out.times.send_ns = msg.send_ns();
    const std::string& bytes = msg.jpeg();
    out.jpeg.assign(bytes.begin(), bytes.end());
    msg.clear_jpeg();
    return {};
}

}  // namespace mogao
