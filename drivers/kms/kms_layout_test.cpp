// SPDX-License-Identifier: Apache-2.0
#include "drivers/kms/kms_layout.h"

#include <gtest/gtest.h>

#include <array>

namespace mogao {
namespace {

drmModeModeInfo mode(std::uint16_t w, std::uint16_t h, std::uint32_t clock_khz, bool preferred = false) {
    drmModeModeInfo m{};
    m.hdisplay = w;
    m.vdisplay = h;
    m.htotal = static_cast<std::uint16_t>(w + 160);
    m.vtotal = static_cast<std::uint16_t>(h + 40);
    m.clock = clock_khz;
    m.type = preferred ? DRM_MODE_TYPE_PREFERRED : 0;
    return m;
}

TEST(PickMode, PrefersPreferredThenAreaThenRefresh) {
    const std::array modes{mode(1920, 1080, 148500), mode(1280, 800, 71000, true), mode(3840, 2160, 594000)};
    EXPECT_EQ(pick_mode(modes), 1u);  // the projector's native mode wins over a bigger one
    const std::array no_preferred{mode(1280, 720, 74250), mode(1920, 1080, 74250), mode(1920, 1080, 148500)};
    EXPECT_EQ(pick_mode(no_preferred), 2u);  // largest, then the higher refresh
    EXPECT_FALSE(pick_mode(std::span<const drmModeModeInfo>{}));
    // video=Virtual-1:1024x768 on the kernel command line: the forced mode wins over the preferred one.
    std::array forced{mode(1920, 1080, 148500, true), mode(1024, 768, 65000), mode(800, 600, 40000)};
    forced[1].type |= DRM_MODE_TYPE_USERDEF;
    EXPECT_EQ(pick_mode(forced), 1u);
}

TEST(RefreshHz, FromClockAndTotals) {
    drmModeModeInfo m = mode(1920, 1080, 148500);
    m.htotal = 2200;
    m.vtotal = 1125;
    EXPECT_NEAR(refresh_hz(m), 60.0, 1e-9);
    m.flags = DRM_MODE_FLAG_INTERLACE;
    EXPECT_NEAR(refresh_hz(m), 120.0, 1e-9);
    m.vtotal = 0;
    EXPECT_EQ(refresh_hz(m), 0.0);
}

TEST(AssignCrtcs, MatchesEveryConnectorItCan) {
    // Greedy would give connector 0 CRTC 0 and leave connector 1 (only CRTC 0) dark.
    const std::array<std::uint32_t, 2> masks{0b11, 0b01};
    const auto a = assign_crtcs(masks, 2);
    ASSERT_TRUE(a[0] && a[1]);
    EXPECT_EQ(*a[0], 1);
    EXPECT_EQ(*a[1], 0);
}

TEST(AssignCrtcs, LeavesOutConnectorsWithoutACrtc) {
    const std::array<std::uint32_t, 3> masks{0b1, 0b1, 0b0};
    const auto a = assign_crtcs(masks, 1);
    EXPECT_EQ(a[0], 0);
    EXPECT_FALSE(a[1]);
    EXPECT_FALSE(a[2]);
    const std::array<std::uint32_t, 1> beyond{0b100};
    EXPECT_FALSE(assign_crtcs(beyond, 2)[0]);  // bit 2 names a CRTC that does not exist
}

TEST(PickPlane, PrimaryBeforeOverlayNeverCursorOrTaken) {
    const std::array planes{
        PlaneCandidate{10, 0b11, DRM_PLANE_TYPE_OVERLAY, true},
        PlaneCandidate{11, 0b01, DRM_PLANE_TYPE_PRIMARY, true},
        PlaneCandidate{12, 0b10, DRM_PLANE_TYPE_PRIMARY, false},  // cannot scan out XRGB8888
        PlaneCandidate{13, 0b10, DRM_PLANE_TYPE_CURSOR, true},
    };
    EXPECT_EQ(pick_plane(planes, 0, {}), 1u);
    EXPECT_EQ(pick_plane(planes, 1, {}), 0u);  // no usable primary on CRTC 1: the overlay
    const std::vector<bool> overlay_taken{true};
    EXPECT_FALSE(pick_plane(planes, 1, overlay_taken));
    EXPECT_FALSE(pick_plane(planes, 40, {}));
}

}  // namespace
}  // namespace mogao
