// SPDX-License-Identifier: Apache-2.0
// Per-appliance view policies: the file (view_policy_file.h), the resolution bound (view_policy.h,
// max_size) and the farm's gate applying each appliance's own policy (policy_gate.h).
#include "renderfarm/farm/view_policy_file.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "renderfarm/farm/policy_gate.h"

namespace mogao {
namespace {

class ViewPolicyFile : public ::testing::Test {
protected:
    std::filesystem::path write(const std::string& text) {
        std::ofstream(path_) << text;
        return path_;
    }
    std::string error_of(const std::string& text) {
        try {
            (void)read_view_policies(write(text), ViewPolicy{});
        } catch (const std::runtime_error& e) {
            return e.what();
        }
        return "(no error)";
    }
    void TearDown() override { std::filesystem::remove(path_); }
    std::filesystem::path path_ =
        std::filesystem::temp_directory_path() / ("mogao-view-policy-" + std::to_string(::getpid()) + ".json");
};

constexpr const char* kTwoMuseums = R"({
  "appliances": {
    "museum-1": {"screen": {"radius_m": 3, "arc_deg": 150, "bottom_m": 0.2, "top_m": 2.8, "eye_height_m": 1.5},
                 "max_guard_deg": 10, "max_size": [1920, 540]},
    "museum-2": {"min_fov_deg": 30}
  }
})";

TEST_F(ViewPolicyFile, EachListedApplianceStartsFromTheFarmPolicyAndReplacesWhatItNames) {
    ViewPolicy farm;
    farm.max_guard_deg = 20.0;
    farm.min_fov_deg = 5.0;
    const ViewPolicies p = read_view_policies(write(kTwoMuseums), farm);
    ASSERT_EQ(p.appliances.size(), 2u);
    const ViewPolicy& one = p.of("museum-1");
    ASSERT_TRUE(one.screen.has_value());
    EXPECT_DOUBLE_EQ(one.screen->arc_deg, 150.0);
    EXPECT_DOUBLE_EQ(one.screen->eye_m.y(), 1.5);
    EXPECT_DOUBLE_EQ(one.max_guard_deg, 10.0);
    EXPECT_EQ(one.max_size, (ImageSize{1920, 540}));
    EXPECT_DOUBLE_EQ(one.min_fov_deg, 5.0);  // from the farm's
    const ViewPolicy& two = p.of("museum-2");
    EXPECT_DOUBLE_EQ(two.min_fov_deg, 30.0);
    EXPECT_DOUBLE_EQ(two.max_guard_deg, 20.0);
    EXPECT_FALSE(two.screen.has_value());
    EXPECT_DOUBLE_EQ(p.of("museum-9").max_guard_deg, 20.0);  // unlisted: the farm's
    EXPECT_DOUBLE_EQ(p.of("").min_fov_deg, 5.0);
}

TEST_F(ViewPolicyFile, BadFilesNameTheFieldAndTheLimit) {
    const auto expect = [&](const std::string& text, const std::string& needle) {
        const std::string e = error_of(text);
        EXPECT_NE(e.find(needle), std::string::npos) << "for " << text << ": " << e;
        EXPECT_NE(e.find(path_.string()), std::string::npos) << e;
    };
    expect("{", "not JSON");
    expect(R"({"appliance": {}})", "(top level).appliance: unknown key");
    expect(R"({"appliances": {"museum-1": {"max_sise": [1, 2]}}})", "appliances.museum-1.max_sise: unknown key");
    expect(R"({"appliances": {"museum-1": {"max_size": [1920]}}})", "appliances.museum-1.max_size: expected [width");
    expect(R"({"appliances": {"museum-1": {"max_size": [8, 8]}}})", "outside [16, 16384]");
    expect(R"({"appliances": {"museum-1": {"max_guard_deg": "wide"}}})", "max_guard_deg: expected a number");
    expect(R"({"appliances": {"museum-1": {"max_guard_deg": 400}}})", "max_guard_deg 400 is outside [0, 180)");
    expect(R"({"appliances": {"museum-1": {"screen": {"radius_m": 3, "arc_deg": 150, "bottom_m": 0}}}})",
           "appliances.museum-1.screen.top_m: missing");
    expect(R"({"appliances": {"museum-1": {"screen": {"radius_m": -3, "arc_deg": 150, "bottom_m": 0, "top_m": 2}}}})",
           "radius > 0");
    expect(R"({"appliances": {"museum-1": {"visitable_area": 1}}})", "expected true or false");
    expect(R"({"appliances": []})", "appliances: expected an object");
    std::filesystem::remove(path_);
    try {
        (void)read_view_policies(path_, ViewPolicy{});
        ADD_FAILURE() << "a missing file was read";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("cannot be read"), std::string::npos) << e.what();
    }
}

ViewRequest huge_pinhole() {
    ViewRequest r;
    r.size = {16384, 16384};
    r.camera = PinholeCamera{};
    r.pose.eye = {0.0, 1.6, 0.0};
    return r;
}

TEST(ViewPolicyMaxSize, ARequestLargerThanTheApplianceIsRenderedAtItsSize) {
    ViewPolicy policy;
    policy.max_size = ImageSize{1920, 1080};
    for (const ImageSize asked : {ImageSize{16384, 16384}, ImageSize{3001, 1000}, ImageSize{1921, 1081}}) {
        ViewRequest r = huge_pinhole();
        r.size = asked;
        const ViewDecision d = apply_view_policy(r, Viewer{}, policy);
        const ImageSize rendered = render_size(d.view);
        EXPECT_LE(rendered.width, 1920) << asked.width << "x" << asked.height;
        EXPECT_LE(rendered.height, 1080) << asked.width << "x" << asked.height;
        // As large as fits: one more pixel on the limiting side would exceed it.
        EXPECT_TRUE(rendered.width >= 1919 || rendered.height >= 1079) << rendered.width << "x" << rendered.height;
        EXPECT_EQ(d.view.size, asked);  // the frame's nominal size is kept
        EXPECT_NE(d.changes.find("resolution_scale"), std::string::npos) << d.changes;
    }
    ViewRequest small = huge_pinhole();
    small.size = {1920, 1080};
    EXPECT_TRUE(apply_view_policy(small, Viewer{}, policy).changes.empty());
    small.size = {3840, 2160};
    small.quality.resolution_scale = 0.25;  // renders 960x540: within the bound, unchanged
    EXPECT_DOUBLE_EQ(apply_view_policy(small, Viewer{}, policy).view.quality.resolution_scale, 0.25);
}

TEST(PolicyGateTest, EachApplianceGetsItsOwnPolicy) {
    Scene scene;
    ViewPolicies policies;
    ViewPolicy small_screen;
    small_screen.screen = CylinderScreen{3.0, 120.0, 0.0, 2.5, {0.0, 1.6, 0.0}};
    small_screen.max_guard_deg = 0.0;
    small_screen.max_size = ImageSize{1280, 360};
    policies.appliances.emplace("museum-1", small_screen);
    RequestPolicy bounds;
    PolicyGate gate(scene, bounds, policies);

    ViewRequest r;
    r.size = {5760, 1080};
    r.camera = CylinderScreen{3.0, 360.0, 0.0, 2.5, {0.0, 1.6, 0.0}};
    r.session = 1;
    const ViewRequest limited = gate.apply(r, "museum-1");
    EXPECT_DOUBLE_EQ(std::get<CylinderScreen>(limited.camera).arc_deg, 120.0);
    EXPECT_LE(render_size(limited).width, 1280);
    EXPECT_LE(render_size(limited).height, 360);
    r.session = 2;
    const ViewRequest other = gate.apply(r, "museum-2");  // unlisted: the farm's default policy
    EXPECT_DOUBLE_EQ(std::get<CylinderScreen>(other.camera).arc_deg, 360.0);
    EXPECT_EQ(render_size(other), (ImageSize{5760, 1080}));
    EXPECT_EQ(gate.changed(), 1u);
}

}  // namespace
}  // namespace mogao
