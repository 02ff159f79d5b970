// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/view_policy.h"

#include <stdexcept>

#include <gtest/gtest.h>

#include "common/request_limits.h"

namespace mogao {
namespace {

Viewer room_viewer() {
    Viewer v;
    v.visitable = VisitableArea{{-4.0, -2.0}, {4.0, 7.0}, {0.0, 0.0}, 0.0, 1.2, 2.0};
    return v;
}

ViewRequest cylinder_request() {
    ViewRequest r;
    r.size = {960, 540};
    r.camera = CylinderScreen{3.0, 150.0, 0.2, 2.8, {0.0, 1.6, 0.0}};
    r.pose.eye = {0.0, 1.6, 5.0};
    return r;
}

TEST(ViewPolicy, AVisitorsViewInsideTheAreaOnTheScreenIsUnchanged) {
    ViewPolicy policy;
    policy.screen = std::get<CylinderScreen>(cylinder_request().camera);
    const ViewRequest r = cylinder_request();
    const ViewDecision d = apply_view_policy(r, room_viewer(), policy);
    EXPECT_TRUE(d.changes.empty()) << d.changes;
    EXPECT_EQ(d.view.pose.eye, r.pose.eye);
    EXPECT_EQ(std::get<CylinderScreen>(d.view.camera).arc_deg, 150.0);
}

TEST(ViewPolicy, AnEyeOutsideTheVisitableAreaIsMovedToItsNearestPoint) {
    ViewRequest r = cylinder_request();
    r.pose.eye = {9.0, 30.0, -5.0};  // outside in x, z and far above the room
    const ViewDecision d = apply_view_policy(r, room_viewer(), ViewPolicy{});
    EXPECT_EQ(d.view.pose.eye, Eigen::Vector3d(4.0, 2.0, -2.0));
    EXPECT_NE(d.changes.find("eye (9, 30, -5) -> (4, 2, -2)"), std::string::npos) << d.changes;
    // Off: the eye stays where it was asked; a scene without an area: anywhere.
    ViewPolicy off;
    off.visitable_area = false;
    EXPECT_EQ(apply_view_policy(r, room_viewer(), off).view.pose.eye, r.pose.eye);
    EXPECT_EQ(apply_view_policy(r, Viewer{}, ViewPolicy{}).view.pose.eye, r.pose.eye);
    // A disc (the grotto's floor): onto its rim, toward the requested eye.
    Viewer disc;
    VisitableArea round;
    round.centre_xz = {1.0, 0.0};
    round.radius_m = 5.0;
    round.eye_min_m = 1.2;
    round.eye_max_m = 2.0;
    disc.visitable = round;
    r.pose.eye = {1.0, 1.6, 10.0};
    const Eigen::Vector3d rim = apply_view_policy(r, disc, ViewPolicy{}).view.pose.eye;
    EXPECT_NEAR((rim - Eigen::Vector3d(1.0, 1.6, 5.0)).norm(), 0.0, 1e-12);
    r.pose.eye = {3.0, 1.6, -1.0};  // inside the disc
    EXPECT_EQ(apply_view_policy(r, disc, ViewPolicy{}).view.pose.eye, r.pose.eye);
}

TEST(ViewPolicy, TheScreenBoundsTheCameraAndAPinholeGetsTheScreensCamera) {
    ViewPolicy policy;
    policy.screen = CylinderScreen{3.0, 150.0, 0.2, 2.8, {0.0, 1.6, 0.0}};
    policy.max_guard_deg = 10.0;
    ViewRequest wide = cylinder_request();
    std::get<CylinderScreen>(wide.camera) = CylinderScreen{0.5, 360.0, -5.0, 9.0, {0.0, 0.2, 0.4}};
    const ViewDecision w = apply_view_policy(wide, room_viewer(), policy);
    const auto& c = std::get<CylinderScreen>(w.view.camera);
    EXPECT_EQ(c.arc_deg, 170.0);  // 150 + 2 x 10 of guard band
    EXPECT_EQ(c.radius_m, 3.0);
    EXPECT_EQ(c.top_m, 2.8);
    EXPECT_EQ(c.eye_m, Eigen::Vector3d(0.0, 1.6, 0.0));
    EXPECT_NE(w.changes.find("arc_deg 360 -> 170"), std::string::npos) << w.changes;
    // The late warp's guard band is allowed.
    ViewRequest guarded = cylinder_request();
    std::get<CylinderScreen>(guarded.camera).arc_deg = 165.0;
    EXPECT_TRUE(apply_view_policy(guarded, room_viewer(), policy).changes.empty());

    ViewRequest zoom = cylinder_request();
    zoom.camera = PinholeCamera{1.0};
    const ViewDecision z = apply_view_policy(zoom, room_viewer(), policy);
    ASSERT_TRUE(std::holds_alternative<CylinderScreen>(z.view.camera)) << z.changes;
    EXPECT_EQ(std::get<CylinderScreen>(z.view.camera).arc_deg, 150.0);
    EXPECT_NO_THROW(validate_view_request(z.view));
}

TEST(ViewPolicy, WithoutAScreenANarrowPinholeIsWidened) {
    ViewPolicy policy;
    policy.min_fov_deg = 30.0;
    ViewRequest zoom = cylinder_request();
    zoom.camera = PinholeCamera{0.5};
    const ViewDecision d = apply_view_policy(zoom, room_viewer(), policy);
    EXPECT_EQ(std::get<PinholeCamera>(d.view.camera).vertical_fov_deg, 30.0);
    EXPECT_NE(d.changes.find("vertical_fov_deg 0.5 -> 30"), std::string::npos) << d.changes;
    zoom.camera = PinholeCamera{60.0};
    EXPECT_TRUE(apply_view_policy(zoom, room_viewer(), policy).changes.empty());
}

TEST(ViewPolicy, BadSettingsAreNamed) {
    const auto message = [](const ViewPolicy& p) {
        try {
            p.validate();
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    ViewPolicy p;
    p.max_guard_deg = 200.0;
    EXPECT_NE(message(p).find("max_guard_deg 200 is outside [0, 180)"), std::string::npos) << message(p);
    p = ViewPolicy{};
    p.min_fov_deg = -1.0;
    EXPECT_NE(message(p).find("min_fov_deg"), std::string::npos) << message(p);
    p = ViewPolicy{};
    p.screen = CylinderScreen{3.0, 150.0, 2.0, 1.0, {0.0, 1.6, 0.0}};
    EXPECT_NE(message(p).find("top above bottom"), std::string::npos) << message(p);
}

}  // namespace
}  // namespace mogao
