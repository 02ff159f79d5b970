// SPDX-License-Identifier: Apache-2.0
// read_gray_image: fixtures are written by an independent encoder (OpenCV's imwrite) or by hand
// (PGM headers), and read back by our libpng/TurboJPEG/PGM reader.
#include "drivers/camera/image_file.h"
#include "tests/support/scratch_dir.h"

#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

namespace mogao {
namespace {

namespace fs = std::filesystem;

class ImageFile : public ::testing::Test {
protected:
    mogao::testing::ScratchDir scratch_{"imagefile"};

    // A gradient, so that row order, column order and every value are checked.
    static cv::Mat gradient(int w, int h) {
        cv::Mat m(h, w, CV_8UC1);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) m.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>((x * 7 + y * 13) % 256);
        return m;
    }
    fs::path write_cv(const std::string& name, const cv::Mat& m) {
        EXPECT_TRUE(cv::imwrite((dir_ / name).string(), m));
        return dir_ / name;
    }
    fs::path write_bytes(const std::string& name, const std::string& bytes) {
        std::ofstream(dir_ / name, std::ios::binary) << bytes;
        return dir_ / name;
    }
    static void expect_equal(const GrayImage& got, const cv::Mat& want, int tolerance) {
        ASSERT_EQ(got.width, want.cols);
        ASSERT_EQ(got.height, want.rows);
        int worst = 0;
        for (int y = 0; y < want.rows; ++y)
            for (int x = 0; x < want.cols; ++x)
                worst = std::max(worst, std::abs(int{got.at(x, y)} - int{want.at<std::uint8_t>(y, x)}));
        EXPECT_LE(worst, tolerance);
    }

    const fs::path dir_ = scratch_.path();
};

TEST_F(ImageFile, GreyPngAndPgmAreExact) {
    const cv::Mat g = gradient(37, 23);
    for (const char* name : {"g.png", "g.pgm"}) {
        auto img = read_gray_image(write_cv(name, g));
        ASSERT_TRUE(img.ok()) << img.error().message;
        expect_equal(*img, g, 0);
    }
}

TEST_F(ImageFile, SixteenBitPngAndPgmScaleTo8Bit) {
    cv::Mat g16(5, 9, CV_16UC1);
    cv::Mat want(5, 9, CV_8UC1);
    for (int y = 0; y < 5; ++y)
        for (int x = 0; x < 9; ++x) {
            const int v8 = (x * 29 + y * 11) % 256;
            g16.at<std::uint16_t>(y, x) = static_cast<std::uint16_t>(v8 * 257);  // exact in 8 bits
            want.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(v8);
        }
    for (const char* name : {"g16.png", "g16.pgm"}) {
        auto img = read_gray_image(write_cv(name, g16));
        ASSERT_TRUE(img.ok()) << name << ": " << img.error().message;
        expect_equal(*img, want, 0);
    }
}

TEST_F(ImageFile, PgmHeaderWithCommentsAndSmallMaxval) {
    // maxval 3: samples 0..3 map to 0, 85, 170, 255.
    auto img = read_gray_image(
        write_bytes("c.pgm", std::string("P5\n# a comment\n4 1 # w h\n3\n") + '\0' + '\1' + '\2' + '\3'));
    ASSERT_TRUE(img.ok()) << img.error().message;
    ASSERT_EQ(img->width, 4);
    EXPECT_EQ(img->at(0, 0), 0);
    EXPECT_EQ(img->at(1, 0), 85);
    EXPECT_EQ(img->at(2, 0), 170);
    EXPECT_EQ(img->at(3, 0), 255);
}

TEST_F(ImageFile, ColourPngAndJpegBecomeLuma) {
    cv::Mat bgr(8, 8, CV_8UC3, cv::Scalar(40, 160, 90));  // B, G, R
    cv::Mat bgr16(8, 8, CV_16UC3, cv::Scalar(40 * 257, 160 * 257, 90 * 257));
    auto png16 = read_gray_image(write_cv("c16.png", bgr16));
    ASSERT_TRUE(png16.ok()) << png16.error().message;
    EXPECT_EQ(png16->at(4, 4), 125);
    cv::Mat bgra(8, 8, CV_8UC4, cv::Scalar(40, 160, 90, 255));  // opaque alpha: same grey
    auto png_alpha = read_gray_image(write_cv("c4.png", bgra));
    ASSERT_TRUE(png_alpha.ok()) << png_alpha.error().message;
    EXPECT_EQ(png_alpha->at(4, 4), 125);
    auto png = read_gray_image(write_cv("c.png", bgr));
    ASSERT_TRUE(png.ok()) << png.error().message;
    EXPECT_EQ(png->at(4, 4), 125);  // BT.601 on the encoded values: 0.299*90 + 0.587*160 + 0.114*40 = 125.39
    auto jpg = read_gray_image(write_cv("c.jpg", bgr));
    ASSERT_TRUE(jpg.ok()) << jpg.error().message;
    EXPECT_NEAR(jpg->at(4, 4), 125, 3);  // JPEG's Y (ITU-T T.871), after lossy coding
}

TEST_F(ImageFile, GreyJpegIsCloseToTheOriginal) {
    const cv::Mat g = gradient(64, 48);
    auto img = read_gray_image(write_cv("g.jpg", g));
    ASSERT_TRUE(img.ok()) << img.error().message;
    ASSERT_EQ(img->width, 64);
    ASSERT_EQ(img->height, 48);
    double sum = 0;
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 64; ++x) sum += std::abs(int{img->at(x, y)} - int{g.at<std::uint8_t>(y, x)});
    EXPECT_LT(sum / (64 * 48), 6.0);  // quality 95 by default; the gradient wraps, so a few edges ring
}

TEST_F(ImageFile, BadFilesAreClearErrorsNamingTheFile) {
    const cv::Mat g = gradient(16, 16);
    std::vector<std::uint8_t> png;
    ASSERT_TRUE(cv::imencode(".png", g, png));
    struct Case {
        std::string name, bytes;
        int code;
        std::string says;
    };
    const std::vector<Case> cases = {
        {"text.png", "this is not a png", EBADMSG, "not a PNG, binary PGM (P5) or JPEG"},
        {"empty.pgm", "", EBADMSG, "not a PNG"},
        {"cut.png", std::string(png.begin(), png.begin() + static_cast<long>(png.size() / 2)), EBADMSG, "bad PNG"},
        {"cut.pgm", "P5 4 4 255\nab", EBADMSG, "truncated PGM"},
        {"huge.pgm", "P5 9000 2 255\n", EBADMSG, "width missing or outside 1..8192"},
        {"zero.pgm", "P5 0 2 255\n", EBADMSG, "width"},
        {"maxval.pgm", "P5 1 1 70000\n\x01\x01", EBADMSG, "maxval"},
        {"sample.pgm", std::string("P5 1 1 100\n") + '\xC8', EBADMSG, "exceeds maxval 100"},
        {"cut.jpg", "\xFF\xD8\xFF\xE0 not really", EBADMSG, "cut.jpg"},
    };
    for (const auto& c : cases) {
        auto img = read_gray_image(write_bytes(c.name, c.bytes));
        ASSERT_FALSE(img.ok()) << c.name;
        EXPECT_EQ(img.code(), c.code) << c.name << ": " << img.error().message;
        EXPECT_NE(img.error().message.find(c.name), std::string::npos) << img.error().message;
        EXPECT_NE(img.error().message.find(c.says), std::string::npos) << c.name << ": " << img.error().message;
    }
}

TEST_F(ImageFile, MissingDirectoryAndOversizedFiles) {
    auto missing = read_gray_image(dir_ / "nope.png");
    ASSERT_FALSE(missing.ok());
    EXPECT_EQ(missing.code(), ENOENT);
    EXPECT_NE(missing.error().message.find("nope.png"), std::string::npos);

    auto folder = read_gray_image(dir_);
    ASSERT_FALSE(folder.ok());
    EXPECT_EQ(folder.code(), EINVAL);

    const fs::path big = dir_ / "big.pgm";
    write_bytes("big.pgm", "P5 8 8 255\n");
    fs::resize_file(big, kMaxImageFileBytes + 1);  // sparse: no disk used
    auto too_big = read_gray_image(big);
    ASSERT_FALSE(too_big.ok());
    EXPECT_EQ(too_big.code(), EFBIG);
    EXPECT_NE(too_big.error().message.find("big.pgm"), std::string::npos);
}

}  // namespace
}  // namespace mogao
