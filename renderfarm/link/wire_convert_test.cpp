// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/link/wire_convert.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

namespace mogao {
namespace {

namespace v1 = link::v1;

ViewRequest cylinder_request() {
    ViewRequest r;
    r.frame_id = 42;
    r.pose.eye = {1.5, 1.6, -2.25};
    r.pose.yaw_deg = -30.5;
    r.pose.pitch_deg = 4.0;
    r.camera = CylinderScreen{3.2, 150.0, 0.2, 2.8, Eigen::Vector3d(0.1, 1.55, 0.0)};
    r.size = {2560, 720};
    r.quality = {16, 2, 4, 3, 0.5, 77};
    r.seed = 99;
    r.request_time_ns = 1'700'000'000'123'456'789;
    return r;
}

TEST(WireConvert, CylinderRequestRoundTripsExactly) {
    const ViewRequest in = cylinder_request();
    v1::ViewRequestMsg msg;
    view_to_msg(in, msg);
    // Through bytes, as on the wire.
    v1::ViewRequestMsg parsed;
    ASSERT_TRUE(parsed.ParseFromString(msg.SerializeAsString()));
    ViewRequest out;
    ASSERT_EQ(view_from_msg(parsed, out), "");
    EXPECT_EQ(out.frame_id, in.frame_id);
    EXPECT_EQ(out.pose.eye, in.pose.eye);
    EXPECT_EQ(out.pose.yaw_deg, in.pose.yaw_deg);
    EXPECT_EQ(out.pose.pitch_deg, in.pose.pitch_deg);
    const auto& c = std::get<CylinderScreen>(out.camera);
    const auto& e = std::get<CylinderScreen>(in.camera);
    EXPECT_EQ(c.radius_m, e.radius_m);
    EXPECT_EQ(c.arc_deg, e.arc_deg);
    EXPECT_EQ(c.bottom_m, e.bottom_m);
    EXPECT_EQ(c.top_m, e.top_m);
    EXPECT_EQ(c.eye_m, e.eye_m);
    EXPECT_EQ(out.size, in.size);
    EXPECT_EQ(out.quality.spp, 16);
    EXPECT_EQ(out.quality.max_bounces, 2);
    EXPECT_EQ(out.quality.ao_samples, 4);
    EXPECT_EQ(out.quality.area_light_samples, 3);
    EXPECT_EQ(out.quality.resolution_scale, 0.5);
    EXPECT_EQ(out.quality.jpeg_quality, 77);
    EXPECT_EQ(out.seed, 99u);
    EXPECT_EQ(out.request_time_ns, in.request_time_ns);
}

TEST(WireConvert, PinholeRequestRoundTrips) {
    ViewRequest in = cylinder_request();
    in.camera = PinholeCamera{72.5};
    v1::ViewRequestMsg msg;
    view_to_msg(in, msg);
    ViewRequest out;
    ASSERT_EQ(view_from_msg(msg, out), "");
    EXPECT_EQ(std::get<PinholeCamera>(out.camera).vertical_fov_deg, 72.5);
}

struct BadCase {
    const char* field;  // must appear in the error
    std::function<void(ViewRequest&)> spoil;
};

TEST(WireConvert, EveryLimitIsCheckedAndNamed) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    const BadCase cases[] = {
        {"request_id", [](ViewRequest& r) { r.frame_id = 0; }},
        {"pose.eye_m.y", [&](ViewRequest& r) { r.pose.eye.y() = nan; }},
        {"pose.yaw_deg", [&](ViewRequest& r) { r.pose.yaw_deg = inf; }},
        {"pose.pitch_deg", [&](ViewRequest& r) { r.pose.pitch_deg = -inf; }},
        {"cylinder.radius_m", [](ViewRequest& r) { std::get<CylinderScreen>(r.camera).radius_m = 0.0; }},
        {"cylinder.arc_deg", [](ViewRequest& r) { std::get<CylinderScreen>(r.camera).arc_deg = 361.0; }},
        {"cylinder.top_m", [](ViewRequest& r) { std::get<CylinderScreen>(r.camera).top_m = 0.1; }},
        {"cylinder.eye_m.z", [&](ViewRequest& r) { std::get<CylinderScreen>(r.camera).eye_m.z() = nan; }},
        {"pinhole.vertical_fov_deg", [](ViewRequest& r) { r.camera = PinholeCamera{180.0}; }},
        {"width", [](ViewRequest& r) { r.size.width = 15; }},
        {"height", [](ViewRequest& r) { r.size.height = 16385; }},
        {"quality.spp", [](ViewRequest& r) { r.quality.spp = 0; }},
        {"quality.spp", [](ViewRequest& r) { r.quality.spp = 4097; }},
        {"quality.max_bounces", [](ViewRequest& r) { r.quality.max_bounces = 65; }},
        {"quality.ao_samples", [](ViewRequest& r) { r.quality.ao_samples = 1025; }},
        {"quality.area_light_samples", [](ViewRequest& r) { r.quality.area_light_samples = 0; }},
        {"quality.resolution_scale", [](ViewRequest& r) { r.quality.resolution_scale = 0.0; }},
        {"quality.resolution_scale", [](ViewRequest& r) { r.quality.resolution_scale = 1.01; }},
        {"quality.resolution_scale", [&](ViewRequest& r) { r.quality.resolution_scale = nan; }},
        {"quality.jpeg_quality", [](ViewRequest& r) { r.quality.jpeg_quality = 101; }},
        {"quality.jpeg_quality", [](ViewRequest& r) { r.quality.jpeg_quality = 0; }},
    };
    for (const auto& c : cases) {
        ViewRequest r = cylinder_request();
        c.spoil(r);
        const std::string direct = validate_link_request(r);
        EXPECT_NE(direct.find(c.field), std::string::npos) << c.field << " -> " << direct;
        v1::ViewRequestMsg msg;
        view_to_msg(r, msg);
        ViewRequest out;
        const std::string wire = view_from_msg(msg, out);
        EXPECT_NE(wire.find(c.field), std::string::npos) << c.field << " -> " << wire;
    }
}

TEST(WireConvert, BoundaryValuesAreAccepted) {
    ViewRequest r = cylinder_request();
    r.size = {16, 16384};
    r.quality = {4096, 64, 1024, 1024, 1.0, 100};
    std::get<CylinderScreen>(r.camera).arc_deg = 360.0;
    EXPECT_EQ(validate_link_request(r), "");
    r.quality = {1, 0, 0, 1, 1e-6, 1};
    EXPECT_EQ(validate_link_request(r), "");
}

TEST(WireConvert, HugeWireValuesAreReportedAsSentNotWrapped) {
    v1::ViewRequestMsg msg;
    view_to_msg(cylinder_request(), msg);
    msg.set_width(4'294'967'295u);
    ViewRequest out;
    EXPECT_EQ(view_from_msg(msg, out), "width = 4294967295 is outside [16, 16384]");
    view_to_msg(cylinder_request(), msg);
    msg.mutable_quality()->set_spp(3'000'000'000u);
    EXPECT_EQ(view_from_msg(msg, out), "quality.spp = 3000000000 is outside [1, 4096]");
}

TEST(WireConvert, NegativeIntsAreSentAsZeroAndRefused) {
    ViewRequest r = cylinder_request();
    r.size.width = -5;
    v1::ViewRequestMsg msg;
    view_to_msg(r, msg);
    EXPECT_EQ(msg.width(), 0u);
    ViewRequest out;
    EXPECT_EQ(view_from_msg(msg, out), "width = 0 is outside [16, 16384]");
}

TEST(WireConvert, MissingSubMessagesAreErrorsNotZeros) {
    v1::ViewRequestMsg full;
    view_to_msg(cylinder_request(), full);
    ViewRequest out;
    v1::ViewRequestMsg m = full;
    m.clear_pose();
    EXPECT_EQ(view_from_msg(m, out), "pose is missing");
    m = full;
    m.clear_quality();
    EXPECT_EQ(view_from_msg(m, out), "quality is missing");
    m = full;
    m.clear_camera();
    EXPECT_EQ(view_from_msg(m, out), "camera is missing (set pinhole or cylinder)");
    m = full;
    m.mutable_cylinder()->clear_eye_m();
    EXPECT_EQ(view_from_msg(m, out), "cylinder.eye_m is missing");
    // An empty message (what garbage often parses to) is refused.
    EXPECT_NE(view_from_msg(v1::ViewRequestMsg{}, out), "");
}

v1::FrameMsg good_frame() {
    v1::FrameMsg f;
    f.set_frame_id(3);
    f.set_request_id(42);
    pose_to_msg(cylinder_request().pose, *f.mutable_pose());
    f.set_request_time_ns(10);
    f.set_received_ns(20);
    f.set_render_start_ns(30);
    f.set_render_end_ns(40);
    f.set_encode_end_ns(50);
    f.set_send_ns(60);
    f.set_width(640);
    f.set_height(360);
    f.set_spp(5);
    f.set_bounces(2);
    f.set_jpeg(std::string("\xff\xd8 fake jpeg", 12));
    return f;
}

TEST(WireConvert, FrameConvertsWithTimestamps) {
    v1::FrameMsg msg = good_frame();
    LinkFrame frame;
    ASSERT_EQ(frame_from_msg(msg, frame), "");
    EXPECT_EQ(frame.frame_id, 3u);
    EXPECT_EQ(frame.request_id, 42u);
    EXPECT_EQ(frame.pose.yaw_deg, -30.5);
    EXPECT_EQ(frame.size, (ImageSize{640, 360}));
    EXPECT_EQ(frame.spp, 5u);
    EXPECT_EQ(frame.bounces, 2u);
    EXPECT_EQ(frame.times.request_ns, 10);
    EXPECT_EQ(frame.times.received_ns, 20);
    EXPECT_EQ(frame.times.render_start_ns, 30);
    EXPECT_EQ(frame.times.render_end_ns, 40);
    EXPECT_EQ(frame.times.encode_end_ns, 50);
    EXPECT_EQ(frame.times.send_ns, 60);
    EXPECT_EQ(frame.jpeg.size(), 12u);
    EXPECT_EQ(frame.jpeg[0], 0xff);
}

TEST(WireConvert, BadFramesAreRefusedByName) {
    LinkFrame frame;
    v1::FrameMsg m = good_frame();
    m.set_width(0);
    EXPECT_NE(frame_from_msg(m, frame).find("frame width"), std::string::npos);
    m = good_frame();
    m.set_height(20000);
    EXPECT_NE(frame_from_msg(m, frame).find("frame height"), std::string::npos);
    m = good_frame();
    m.clear_jpeg();
    EXPECT_EQ(frame_from_msg(m, frame), "frame jpeg is empty");
    m = good_frame();
    m.clear_pose();
    EXPECT_EQ(frame_from_msg(m, frame), "frame pose is missing");
    m = good_frame();
    m.mutable_pose()->set_yaw_deg(std::numeric_limits<double>::quiet_NaN());
    EXPECT_NE(frame_from_msg(m, frame).find("pose.yaw_deg"), std::string::npos);
    m = good_frame();
    m.set_frame_id(0);
    EXPECT_NE(frame_from_msg(m, frame), "");
}

}  // namespace
}  // namespace mogao
