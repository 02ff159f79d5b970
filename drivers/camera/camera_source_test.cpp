// SPDX-License-Identifier: Apache-2.0
#include "drivers/camera/camera_source.h"

#include <gtest/gtest.h>

#include <cerrno>

namespace mogao {
namespace {

TEST(CameraSource, ParsesReplayAndV4l2Names) {
    CameraSourceSpec spec;
    std::string why;
    ASSERT_TRUE(parse_camera_source("replay:out/hand-sequence", spec, &why)) << why;
    EXPECT_EQ(spec.kind, CameraSourceSpec::Kind::replay);
    EXPECT_EQ(spec.folder, std::filesystem::path("out/hand-sequence"));
    ASSERT_TRUE(parse_camera_source("v4l2:/dev/video2", spec, &why)) << why;
    EXPECT_EQ(spec.kind, CameraSourceSpec::Kind::v4l2);
    EXPECT_EQ(spec.device, "/dev/video2");
}

TEST(CameraSource, ParsesLibcameraNamesWithOrWithoutAnId) {
    CameraSourceSpec spec;
    std::string why;
    ASSERT_TRUE(parse_camera_source("libcamera:/base/platform/vivid.0-0000", spec, &why)) << why;
    EXPECT_EQ(spec.kind, CameraSourceSpec::Kind::libcamera);
    EXPECT_EQ(spec.camera_id, "/base/platform/vivid.0-0000");
    ASSERT_TRUE(parse_camera_source("libcamera:", spec, &why)) << why;  // the first camera libcamera lists
    EXPECT_EQ(spec.kind, CameraSourceSpec::Kind::libcamera);
    EXPECT_TRUE(spec.camera_id.empty());
}

TEST(CameraSource, RejectsOtherNamesSayingWhy) {
    for (const char* bad : {"", "replay:", "v4l2:", "/dev/video0", "usb:0", "REPLAY:x"}) {
        CameraSourceSpec spec;
        std::string why;
        EXPECT_FALSE(parse_camera_source(bad, spec, &why)) << bad;
        EXPECT_FALSE(why.empty()) << bad;
    }
}

TEST(CameraSource, OpeningAMissingSourceIsAnErrorNotACrash) {
    CameraSourceSpec replay;
    replay.folder = "/nonexistent/mogao-replay";
    const auto r = open_camera_source(replay);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.code(), ENOENT);
    CameraSourceSpec v4l2;
    v4l2.kind = CameraSourceSpec::Kind::v4l2;
    v4l2.device = "/nonexistent/video9";
    EXPECT_FALSE(open_camera_source(v4l2).ok());
}

// A libcamera camera that is not there is an error naming it (ENODEV), or ENOTSUP when the build
// has no libcamera: never a crash or a hang. (A machine with a real camera of that id cannot exist.)
TEST(CameraSource, OpeningAnUnknownLibcameraCameraNamesIt) {
    CameraSourceSpec spec;
    spec.kind = CameraSourceSpec::Kind::libcamera;
    spec.camera_id = "no-such-camera-mogao";
    const auto r = open_camera_source(spec);
    ASSERT_FALSE(r.ok());
    EXPECT_TRUE(r.code() == ENODEV || r.code() == ENOTSUP) << r.error().message;
    if (r.code() == ENODEV) {
        EXPECT_NE(r.error().message.find("no-such-camera-mogao"), std::string::npos) << r.error().message;
    }
}

}  // namespace
}  // namespace mogao
