// SPDX-License-Identifier: Apache-2.0
// The bench calibration's projector lens as the on-site calibration's projector prior: the conversion, the scaling to
// the device, and a site file naming a procam file for one of its projectors.
#include "kiosk/calibrate/procam_command.h"

#include <unistd.h>

#include <gtest/gtest.h>

#include <fstream>

#include "kiosk/calibrate/on_site_job.h"

namespace mogao::calibrate {
namespace {

procam::Intrinsics bench() {
    return procam::Intrinsics{{1024, 768}, cv::Matx33d(1800.0, 0, 511.0, 0, 1790.0, 700.0, 0, 0, 1), {0.1, 0, 0, 0, 0}};
}

autocal::CalibrationPrior one_projector(ImageSize size) {
    autocal::CalibrationPrior prior;
    autocal::DeviceModel d;
    d.id = "proj0";
    d.resolution = size;
    d.fx_px = d.fy_px = 1000.0;
    prior.projectors.push_back(d);
    return prior;
}

TEST(ProcamPrior, MovesPixelCentresAndScalesToTheDevice) {
    const autocal::BenchLens lens = bench_lens_from_procam(bench(), "bench.json");
    EXPECT_DOUBLE_EQ(lens.cx_px, 511.5);  // OpenCV's centre 511 (integer) is autocal's 511.5
    EXPECT_DOUBLE_EQ(lens.cy_px, 700.5);
    const autocal::CalibrationPrior same = autocal::with_bench_lenses(one_projector({1024, 768}), {lens});
    EXPECT_EQ(same.projectors[0].id, "proj0");
    EXPECT_DOUBLE_EQ(same.projectors[0].fx_px, 1800.0);
    EXPECT_DOUBLE_EQ(same.projectors[0].fy_px, 1790.0);
    EXPECT_DOUBLE_EQ(same.projectors[0].cx_px, 511.5);
    EXPECT_DOUBLE_EQ(same.projectors[0].distortion[0], 0.1);  // dimensionless: carried as measured
    const autocal::CalibrationPrior half = autocal::with_bench_lenses(one_projector({512, 384}), {lens});
    EXPECT_DOUBLE_EQ(half.projectors[0].fx_px, 900.0);
    EXPECT_DOUBLE_EQ(half.projectors[0].cx_px, 255.75);  // the pixel edge 0 stays 0: (511 + 0.5) / 2
    EXPECT_DOUBLE_EQ(half.projectors[0].distortion[0], 0.1);
    const autocal::CalibrationPrior none = autocal::with_bench_lenses(one_projector({1024, 768}), {std::nullopt});
    EXPECT_DOUBLE_EQ(none.projectors[0].fx_px, 1000.0);  // no bench file: the data sheet's
    try {
        (void)autocal::with_bench_lenses(one_projector({1920, 1080}), {lens});
        ADD_FAILURE() << "a 16:9 device took a 4:3 bench's lens";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("bench.json"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("1024x768"), std::string::npos) << e.what();
    }
}

// A site file whose second projector names a procam file beside it: the on-site prior takes that projector's
// intrinsics from the file (scaled with the job), the first keeps its data sheet's; a missing file is refused
// naming the site file's field.
TEST(ProcamPrior, ASiteFileNamesItsProjectorsBenchFile) {
    const auto dir = std::filesystem::temp_directory_path() / ("mogao-procam-site-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "lens.json") << R"({"format": "mogao-procam 1", "projector": {"size": [1920, 1080],
        "K": [2050.0, 0, 959.0, 0, 2049.0, 1079.0, 0, 0, 1], "dist": [-0.04, 0.01, 0, 0, 0]}})";
    const std::string projector = "resolution = [1920, 1080]\nthrow_ratio = 1.0\nlens_shift = [0.0, 0.0]\n";
    std::ofstream(dir / "site.toml") << "[screen]\nradius_m = 3.0\narc_deg = 150.0\nbottom_m = 0.8\ntop_m = 2.3\n"
                                     << "[camera]\nresolution = [1280, 720]\n"
                                     << "[[projectors]]\nid = \"left\"\n"
                                     << projector << "[[projectors]]\nid = \"middle\"\nprocam = \"lens.json\"\n"
                                     << projector;
    OnSiteJob job;
    job.site = dir / "site.toml";
    job.scale = 0.5;
    const autocal::CalibrationPrior prior = site_prior(job);
    ASSERT_EQ(prior.projectors.size(), 2U);
    EXPECT_DOUBLE_EQ(prior.projectors[0].fx_px, 960.0);  // throw ratio 1 x 960 px
    EXPECT_DOUBLE_EQ(prior.projectors[0].cy_px, 270.0);  // lens shift 0
    EXPECT_DOUBLE_EQ(prior.projectors[1].fx_px, 1025.0);
    EXPECT_DOUBLE_EQ(prior.projectors[1].cy_px, 539.75);  // (1079 + 0.5) / 2
    EXPECT_DOUBLE_EQ(prior.projectors[1].distortion[0], -0.04);

    std::filesystem::remove(dir / "lens.json");
    try {
        (void)site_prior(job);
        ADD_FAILURE() << "a missing procam file was not refused";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("projectors[1].procam"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("lens.json"), std::string::npos) << e.what();
    }
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace mogao::calibrate
