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

}  // namespace
}  // namespace mogao
