// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/camera_intrinsics.h"
#include "tests/support/scratch_dir.h"

#include <unistd.h>

#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/core.hpp>

namespace mogao {
namespace {

namespace fs = std::filesystem;

class CalibrationFile : public ::testing::Test {
protected:
    mogao::testing::ScratchDir scratch_{"intrinsics"};
    fs::path write(const std::string& name, const std::string& text) {
        std::ofstream(dir_ / name) << text;
        return dir_ / name;
    }
    // The message of the CalibrationFileError read_intrinsics throws for `path`.
    static std::string error_of(const fs::path& path) {
        try {
            (void)read_intrinsics(path);
        } catch (const CalibrationFileError& e) {
            return e.what();
        }
        return "no error";
    }
    const fs::path dir_ = scratch_.path();
};

CameraIntrinsics example() {
    CameraIntrinsics c;
    c.width = 800;
    c.height = 600;
    c.fx = 701.5;
    c.fy = 699.25;
    c.cx = 401.0;
    c.cy = 298.5;
    c.distortion = {0.1, -0.2, 0.001, -0.002, 0.0};
    return c;
}

TEST_F(CalibrationFile, JsonRoundTrip) {
    write_intrinsics(dir_ / "cam.json", example(), 0.21);
    const CameraIntrinsics c = read_intrinsics(dir_ / "cam.json");
    EXPECT_EQ(c.width, 800);
    EXPECT_EQ(c.height, 600);
    EXPECT_EQ(c.fx, 701.5);
    EXPECT_EQ(c.fy, 699.25);
    EXPECT_EQ(c.cx, 401.0);
    EXPECT_EQ(c.cy, 298.5);
    EXPECT_EQ(c.distortion, example().distortion);
}

TEST_F(CalibrationFile, OpenCvYamlAsWrittenByFileStorage) {
    {
        cv::FileStorage fs((dir_ / "cam.yml").string(), cv::FileStorage::WRITE);
        fs << "image_width" << 640 << "image_height" << 480;
        fs << "camera_matrix" << cv::Mat(cv::Matx33d(500, 0, 320, 0, 505, 240, 0, 0, 1));
        fs << "distortion_coefficients" << cv::Mat(cv::Matx<double, 5, 1>(0.01, 0.02, 0, 0, 0));
    }
    const CameraIntrinsics c = read_intrinsics(dir_ / "cam.yml");
    EXPECT_EQ(c.width, 640);
    EXPECT_EQ(c.fx, 500.0);
    EXPECT_EQ(c.fy, 505.0);
    EXPECT_EQ(c.cx, 320.0);
    EXPECT_EQ(c.cy, 240.0);
    ASSERT_EQ(c.distortion.size(), 5U);
    EXPECT_EQ(c.distortion[1], 0.02);
}

TEST_F(CalibrationFile, ErrorsNameFileFieldAndLimit) {
    EXPECT_NE(error_of(write("a.json", R"({"image_width": 800, "image_height": 600, "fx": 700, "fy": 700, "cx": 400})"))
                  .find("a.json: missing field \"cy\""),
              std::string::npos);
    EXPECT_NE(error_of(write("b.json",
                             R"({"image_width": 800, "image_height": 600, "fx": -1, "fy": 700, "cx": 400, "cy": 300})"))
                  .find("fx and fy must be finite and > 0"),
              std::string::npos);
    EXPECT_NE(
        error_of(write("c.json", R"({"image_width": 0, "image_height": 600, "fx": 1, "fy": 1, "cx": 0, "cy": 0})"))
            .find("\"image_width\" = 0 outside [1, 8192]"),
        std::string::npos);
    EXPECT_NE(error_of(write("d.json",
                             R"({"image_width": 800, "image_height": 600, "fx": 700, "fy": 700, "cx": 400, "cy": 300,
                                          "distortion": [1, 2, 3]})"))
                  .find("3 distortion coefficients"),
              std::string::npos);
    EXPECT_NE(
        error_of(
            write("e.json", R"({"image_width": 800, "image_height": 600, "fx": 700, "fy": 700, "cx": 900, "cy": 300})"))
            .find("cx 900"),
        std::string::npos);
    EXPECT_NE(error_of(write("f.json", "{ not json")).find("f.json: not valid JSON"), std::string::npos);
    EXPECT_NE(error_of(write("g.txt", "")).find("unknown calibration format '.txt'"), std::string::npos);
    EXPECT_NE(error_of(dir_ / "missing.json").find("missing.json: cannot be read"), std::string::npos);
    EXPECT_NE(error_of(write("h.yml", "%YAML:1.0\nimage_width: 800\n")).find("h.yml"), std::string::npos);
}

TEST(CameraIntrinsics, RescaleKeepsPixelAreasAligned) {
    CameraIntrinsics c = example();
    c.cx = 399.5;  // the exact image centre in OpenCV's convention
    c.cy = 299.5;
    const CameraIntrinsics half = rescale(c, 400, 300);
    EXPECT_EQ(half.fx, 701.5 / 2);
    EXPECT_EQ(half.cx, 199.5);  // still the exact centre
    EXPECT_EQ(half.cy, 149.5);
    EXPECT_EQ(half.distortion, c.distortion);  // distortion acts on normalised coordinates
    EXPECT_THROW((void)rescale(c, 0, 300), std::invalid_argument);
}

}  // namespace
}  // namespace mogao
