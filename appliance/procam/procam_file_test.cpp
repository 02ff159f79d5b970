// SPDX-License-Identifier: Apache-2.0
// The procam file (write, then read the projector prior back) and bad input: malformed files,
// capture folders with a missing, mis-sized or extra image, a board that is not in the capture.
#include <gtest/gtest.h>

#include <fstream>

#include "appliance/procam/capture_folder.h"
#include "appliance/procam/procam_calibration.h"
#include "appliance/procam/procam_error.h"
#include "common/png_io.h"

namespace mogao::procam {
namespace {

std::filesystem::path temp_dir(const std::string& name) {
    const auto dir =
        std::filesystem::temp_directory_path() / ("mogao-procam-" + name + "-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

// The message of the ProcamError `f` throws ("" if none).
template <typename F>
std::string error_of(F f) {
    try {
        f();
    } catch (const ProcamError& e) {
        return e.what();
    }
    return "";
}

ProcamCalibration sample() {
    ProcamCalibration c;
    c.camera = Intrinsics{{1280, 1024}, cv::Matx33d(2000, 0, 640, 0, 2001, 510, 0, 0, 1), {0.1, -0.2, 0, 0, 0}};
    c.projector = Intrinsics{{1024, 768}, cv::Matx33d(1700, 0, 500, 0, 1702, 700, 0, 0, 1), {-0.05, 0.3, 1e-3, 0, 0}};
    c.R = cv::Matx33d::eye();
    c.T = cv::Vec3d(-150, 20, 30);
    c.rms = 0.25;
    c.captures.push_back({"capture_0", 63, 0.2, 0.3});
    return c;
}

void write_text(const std::filesystem::path& p, const std::string& text) { std::ofstream(p) << text; }

TEST(ProcamFile, ProjectorPriorReadsBackWhatWasWritten) {
    const auto dir = temp_dir("file");
    const ProcamCalibration c = sample();
    const nlohmann::json j = procam_json(c, {{"capture_0", 63, 0.3, 0.6, 0.9}});
    write_procam_file(dir / "procam.json", j);
    const Intrinsics p = read_procam_projector(dir / "procam.json");
    EXPECT_EQ(p.size.width, 1024);
    EXPECT_EQ(p.size.height, 768);
    for (int i = 0; i < 9; ++i) EXPECT_DOUBLE_EQ(p.K.val[i], c.projector.K.val[i]);
    for (std::size_t i = 0; i < 5; ++i) EXPECT_DOUBLE_EQ(p.dist[i], c.projector.dist[i]);
    EXPECT_EQ(j["T"][0].get<double>(), -150.0);
    EXPECT_EQ(j["held_out"][0]["p95_px"].get<double>(), 0.6);
    std::filesystem::remove_all(dir);
}

TEST(ProcamFile, MalformedFilesAreRefusedNamingFileAndField) {
    const auto dir = temp_dir("bad");
    const auto file = dir / "procam.json";
    EXPECT_NE(error_of([&] { (void)read_procam_projector(file); }).find("procam.json: cannot be read"),
              std::string::npos);
    write_text(file, "{ not json");
    EXPECT_NE(error_of([&] { (void)read_procam_projector(file); }).find("not JSON"), std::string::npos);
    nlohmann::json j = procam_json(sample());
    j["format"] = "other 2";
    write_procam_file(file, j);
    EXPECT_NE(error_of([&] { (void)read_procam_projector(file); }).find("format must be"), std::string::npos);
    j = procam_json(sample());
    j["projector"]["K"][2] = 5000.0;
    write_procam_file(file, j);
    EXPECT_NE(error_of([&] { (void)read_procam_projector(file); }).find("projector.K: the principal point"),
              std::string::npos);
    j = procam_json(sample());
    j["projector"]["dist"] = {0.1, 0.2};
    write_procam_file(file, j);
    EXPECT_NE(error_of([&] { (void)read_procam_projector(file); }).find("projector.dist must be an array of 5"),
              std::string::npos);
    j = procam_json(sample());
    j["projector"]["K"][4] = "x";
    write_procam_file(file, j);
    EXPECT_NE(error_of([&] { (void)read_procam_projector(file); }).find("projector.K[4] must be a number"),
              std::string::npos);
    std::filesystem::remove_all(dir);
}

TEST(CaptureFolder, MissingMisSizedAndExtraImagesAreNamed) {
    const auto dir = temp_dir("folder");
    const GrayLayout layout = gray_layout({4, 4});  // 2 + 2 bits: 10 images
    for (int i = 0; i < layout.image_count(); ++i) write_png(dir / capture_file_name(i), Rgb8Image({32, 24}, 100));
    EXPECT_EQ(load_capture_folder(dir, layout).size(), 10u);
    write_png(dir / capture_file_name(3), Rgb8Image({32, 20}, 100));
    EXPECT_NE(error_of([&] {
                  (void)load_capture_folder(dir, layout);
              }).find("graycode_03.png: 32x20 differs from graycode_00.png's 32x24"),
              std::string::npos);
    std::filesystem::remove(dir / capture_file_name(3));
    EXPECT_NE(error_of([&] { (void)load_capture_folder(dir, layout); }).find("graycode_03.png: missing"),
              std::string::npos);
    write_png(dir / capture_file_name(3), Rgb8Image({32, 24}, 100));
    write_png(dir / capture_file_name(10), Rgb8Image({32, 24}, 100));
    EXPECT_NE(error_of([&] {
                  (void)load_capture_folder(dir, layout);
              }).find("graycode_10.png: unexpected; a 4x4 projector has 10 images"),
              std::string::npos);
    write_text(dir / capture_file_name(10), "");
    std::filesystem::remove(dir / capture_file_name(10));
    write_text(dir / capture_file_name(5), "not a png");
    EXPECT_NE(error_of([&] { (void)load_capture_folder(dir, layout); }).find("graycode_05.png: cannot be read as PNG"),
              std::string::npos);
    std::filesystem::remove_all(dir);
}

TEST(CaptureFolder, ABoardNotInTheCaptureIsNamed) {
    const cv::Mat white(240, 320, CV_8UC1, cv::Scalar(200));
    DecodedPixels d{cv::Mat(240, 320, CV_32SC2, cv::Scalar(-1, -1))};
    const std::string e = error_of([&] { (void)observe_board("capture_9", white, d, BoardSpec{9, 7, 75.0}); });
    EXPECT_NE(e.find("capture_9: the 9x7 inner corners of the board are not all found"), std::string::npos) << e;
}

}  // namespace
}  // namespace mogao::procam
