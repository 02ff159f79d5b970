// SPDX-License-Identifier: Apache-2.0
// The bench calibration's projector intrinsics as the on-site calibration's projector prior.
#include "kiosk/calibrate/procam_command.h"

#include <gtest/gtest.h>

namespace mogao::calibrate {
namespace {

procam::Intrinsics bench() {
    return procam::Intrinsics{{1024, 768}, cv::Matx33d(1800.0, 0, 511.0, 0, 1790.0, 700.0, 0, 0, 1), {0.1, 0, 0, 0, 0}};
}

TEST(ProcamPrior, MovesPixelCentresAndScalesToTheDevice) {
    autocal::DeviceModel d;
    d.id = "proj0";
    d.resolution = {1024, 768};
    const autocal::DeviceModel same = projector_prior_from_procam(d, bench());
    EXPECT_EQ(same.id, "proj0");
    EXPECT_DOUBLE_EQ(same.fx_px, 1800.0);
    EXPECT_DOUBLE_EQ(same.fy_px, 1790.0);
    EXPECT_DOUBLE_EQ(same.cx_px, 511.5);  // OpenCV's centre 511 (integer) is autocal's 511.5
    EXPECT_DOUBLE_EQ(same.cy_px, 700.5);
    d.resolution = {512, 384};
    const autocal::DeviceModel half = projector_prior_from_procam(d, bench());
    EXPECT_DOUBLE_EQ(half.fx_px, 900.0);
    EXPECT_DOUBLE_EQ(half.cx_px, 255.75);  // the pixel edge 0 stays 0: (511 + 0.5) / 2
    d.resolution = {1920, 1080};
    EXPECT_THROW((void)projector_prior_from_procam(d, bench()), std::invalid_argument);
}

}  // namespace
}  // namespace mogao::calibrate
