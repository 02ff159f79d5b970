// SPDX-License-Identifier: Apache-2.0
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <variant>

#include <gtest/gtest.h>

#include "common/request_limits.h"

namespace mogao {
namespace {

// Expects begin_frame to throw std::invalid_argument whose message contains every `needle`.
void expect_rejected(const std::function<void(ViewRequest&)>& edit, const std::string& field,
                     const std::string& limit) {
    ViewRequest request;
    request.size = {64, 32};
    edit(request);
    try {
        validate_view_request(request);
        ADD_FAILURE() << "accepted a request with bad " << field;
    } catch (const std::invalid_argument& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(field), std::string::npos) << message;
        EXPECT_NE(message.find(limit), std::string::npos) << message;
    }
}

TEST(ViewValidation, RejectsEachOutOfRangeFieldByName) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    expect_rejected([](ViewRequest& r) { r.quality.spp = 0; }, "quality.spp", "[1, 4096]");
    expect_rejected([](ViewRequest& r) { r.quality.spp = 4097; }, "quality.spp", "[1, 4096]");
    expect_rejected([](ViewRequest& r) { r.shading_one_in = 0; }, "shading_one_in", "[1, 16]");
    expect_rejected([](ViewRequest& r) { r.shading_one_in = 4, r.shading_phase = 4; }, "shading_phase", "[0, 3]");
    expect_rejected([](ViewRequest& r) { r.quality.max_bounces = -1; }, "quality.max_bounces", "[0, 64]");
    expect_rejected([](ViewRequest& r) { r.quality.max_bounces = 65; }, "quality.max_bounces", "[0, 64]");
    expect_rejected([](ViewRequest& r) { r.quality.ao_samples = -1; }, "quality.ao_samples", "[0, 1024]");
    expect_rejected([](ViewRequest& r) { r.quality.ao_samples = 1025; }, "quality.ao_samples", "[0, 1024]");
    expect_rejected([](ViewRequest& r) { r.quality.area_light_samples = 0; }, "quality.area_light_samples",
                    "[1, 1024]");
    expect_rejected([](ViewRequest& r) { r.quality.resolution_scale = 0.0; }, "quality.resolution_scale", "(0, 1]");
    expect_rejected([](ViewRequest& r) { r.quality.resolution_scale = 1.5; }, "quality.resolution_scale", "(0, 1]");
    expect_rejected([nan](ViewRequest& r) { r.quality.resolution_scale = nan; }, "quality.resolution_scale", "(0, 1]");
    expect_rejected([](ViewRequest& r) { r.size.width = 0; }, "size.width", "[1, 16384]");
    expect_rejected([](ViewRequest& r) { r.size.height = 16385; }, "size.height", "[1, 16384]");
    expect_rejected([nan](ViewRequest& r) { r.pose.eye.y() = nan; }, "pose.eye.y", "finite");
    expect_rejected([inf](ViewRequest& r) { r.pose.yaw_deg = inf; }, "pose.yaw_deg", "finite");
    expect_rejected([nan](ViewRequest& r) { r.pose.pitch_deg = nan; }, "pose.pitch_deg", "finite");
    expect_rejected([](ViewRequest& r) { r.camera = PinholeCamera{180.0}; }, "camera.vertical_fov_deg", "(0, 180)");
    expect_rejected(
        [](ViewRequest& r) {
            r.camera = CylinderScreen{0.0, 180.0, 0.0, 2.5, {0.0, 1.6, 0.0}};
        },
        "camera.radius_m", "(0, inf)");
    expect_rejected(
        [](ViewRequest& r) {
            r.camera = CylinderScreen{3.0, 0.0, 0.0, 2.5, {0.0, 1.6, 0.0}};
        },
        "camera.arc_deg", "(0, 360]");
    expect_rejected(
        [](ViewRequest& r) {
            r.camera = CylinderScreen{3.0, 361.0, 0.0, 2.5, {0.0, 1.6, 0.0}};
        },
        "camera.arc_deg", "(0, 360]");
    expect_rejected(
        [](ViewRequest& r) {
            r.camera = CylinderScreen{3.0, 180.0, 2.5, 2.5, {0.0, 1.6, 0.0}};
        },
        "camera.top_m", "(bottom_m, inf)");
}

// Numerical stability: NaN and +-inf in every floating-point field of a view request
// are refused naming the field (a NaN fails every comparison, so a check written as `v <= 0` would
// let it through).
TEST(ViewValidation, RejectsNanAndInfinityInEveryFloatingPointField) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    const auto cylinder = [](ViewRequest& r) -> CylinderScreen& {
        r.camera = CylinderScreen{};
        return std::get<CylinderScreen>(r.camera);
    };
    for (const double bad : {nan, inf, -inf}) {
        expect_rejected([bad](ViewRequest& r) { r.pose.eye.x() = bad; }, "pose.eye.x", "");
        expect_rejected([bad](ViewRequest& r) { r.pose.eye.z() = bad; }, "pose.eye.z", "");
        expect_rejected([bad](ViewRequest& r) { r.pose.yaw_deg = bad; }, "pose.yaw_deg", "");
        expect_rejected([bad](ViewRequest& r) { r.pose.pitch_deg = bad; }, "pose.pitch_deg", "");
        expect_rejected([bad](ViewRequest& r) { r.quality.resolution_scale = bad; }, "quality.resolution_scale", "");
        expect_rejected([bad](ViewRequest& r) { r.camera = PinholeCamera{bad}; }, "camera.vertical_fov_deg", "");
        expect_rejected([&](ViewRequest& r) { cylinder(r).radius_m = bad; }, "camera.radius_m", "");
        expect_rejected([&](ViewRequest& r) { cylinder(r).arc_deg = bad; }, "camera.arc_deg", "");
        expect_rejected([&](ViewRequest& r) { cylinder(r).bottom_m = bad; }, "camera.", "");
        expect_rejected([&](ViewRequest& r) { cylinder(r).top_m = bad; }, "camera.top_m", "");
        expect_rejected([&](ViewRequest& r) { cylinder(r).eye_m.x() = bad; }, "camera.eye_m.x", "");
        expect_rejected([&](ViewRequest& r) { cylinder(r).eye_m.y() = bad; }, "camera.eye_m.y", "");
        expect_rejected([&](ViewRequest& r) { cylinder(r).eye_m.z() = bad; }, "camera.eye_m.z", "");
    }
}

TEST(ViewValidation, AcceptsLimitsAndScalesRenderSize) {
    ViewRequest request;
    request.size = {1920, 1080};
    request.quality.spp = 4096;
    request.quality.max_bounces = 64;
    request.quality.ao_samples = 1024;
    request.quality.resolution_scale = 0.5;
    request.camera = CylinderScreen{3.0, 360.0, 0.0, 2.5, {0.0, 1.6, 0.0}};
    EXPECT_EQ(render_size_for(request), (ImageSize{960, 540}));
    request.quality.resolution_scale = 1e-6;
    EXPECT_EQ(render_size_for(request), (ImageSize{1, 1}));
    request.size = {16384, 3};
    request.quality.resolution_scale = 1.0 / 3.0;
    EXPECT_EQ(render_size_for(request), (ImageSize{5461, 1}));
}

}  // namespace
}  // namespace mogao
