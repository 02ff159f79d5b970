// SPDX-License-Identifier: Apache-2.0
// Our Gray-code decoder on patterns we render (exact codes known), and the local homographies on a
// decoded map made from a known homography.
#include "appliance/procam/gray_decode.h"

#include <gtest/gtest.h>

#include <random>

#include <opencv2/calib3d.hpp>

#include "appliance/procam/local_homography.h"

namespace mogao::procam {
namespace {

// A camera that sees projector pixel (x / 2, y / 2) at camera pixel (x, y) on a surface of albedo
// varying across the image (0.3 .. 0.9, a dark board square to a white one), with ambient light, a
// shadow in the top-left corner (no projector light) and noise of sigma 2 grey levels.
std::vector<cv::Mat> film(const std::vector<cv::Mat>& patterns, cv::Size camera, cv::Rect shadow) {
    std::mt19937 rng(7);
    std::normal_distribution<double> noise(0.0, 2.0);
    std::vector<cv::Mat> out;
    for (const cv::Mat& p : patterns) {
        cv::Mat c(camera, CV_8UC1);
        for (int y = 0; y < camera.height; ++y) {
            for (int x = 0; x < camera.width; ++x) {
                const double albedo = 0.3 + 0.6 * x / camera.width;
                const double light = shadow.contains({x, y}) ? 0.0 : p.at<std::uint8_t>(y / 2, x / 2) / 255.0;
                c.at<std::uint8_t>(y, x) = cv::saturate_cast<std::uint8_t>(20.0 + 200.0 * albedo * light + noise(rng));
            }
        }
        out.push_back(c);
    }
    return out;
}

TEST(GrayDecode, LayoutFollowsOpenCvOrder) {
    const GrayLayout l = gray_layout({1024, 768});
    EXPECT_EQ(l.column_bits, 10);
    EXPECT_EQ(l.row_bits, 10);
    EXPECT_EQ(l.white_index(), 40);
    EXPECT_EQ(l.black_index(), 41);
    const std::vector<cv::Mat> p = render_gray_patterns({1024, 768});
    ASSERT_EQ(p.size(), 42u);
    // Image 0: the columns' most significant Gray bit, white from column 512; image 1 its inverse.
    EXPECT_EQ(p[0].at<std::uint8_t>(0, 511), 0);
    EXPECT_EQ(p[0].at<std::uint8_t>(0, 512), 255);
    EXPECT_EQ(p[1].at<std::uint8_t>(0, 512), 0);
    // Image 18: the least significant column bit, Gray 0110 repeating; image 20: the rows' first.
    EXPECT_EQ(p[18].at<std::uint8_t>(0, 0), 0);
    EXPECT_EQ(p[18].at<std::uint8_t>(0, 1), 255);
    EXPECT_EQ(p[18].at<std::uint8_t>(0, 2), 255);
    EXPECT_EQ(p[18].at<std::uint8_t>(0, 3), 0);
    EXPECT_EQ(p[20].at<std::uint8_t>(511, 0), 0);  // 10 row bits for 768 rows: the first splits at 512
    EXPECT_EQ(p[20].at<std::uint8_t>(512, 0), 255);
    EXPECT_THROW((void)gray_layout({1, 768}), std::invalid_argument);
}

TEST(GrayDecode, DecodesEveryLitPixelExactly) {
    const ImageSize projector{100, 60};  // not powers of two: codes beyond the size exist
    const GrayLayout layout = gray_layout(projector);
    const cv::Rect shadow(0, 0, 30, 20);
    const std::vector<cv::Mat> camera = film(render_gray_patterns(projector), {200, 120}, shadow);
    const DecodedPixels d = decode_gray(camera, layout);
    int wrong = 0;
    for (int y = 0; y < 120; ++y) {
        for (int x = 0; x < 200; ++x) {
            const cv::Vec2i p = d.projector.at<cv::Vec2i>(y, x);
            if (shadow.contains({x, y})) {
                wrong += p[0] != -1 ? 1 : 0;
            } else {
                wrong += p != cv::Vec2i(x / 2, y / 2) ? 1 : 0;
            }
        }
    }
    EXPECT_EQ(wrong, 0);
    EXPECT_EQ(d.lit_pixels, 200 * 120 - shadow.area());
    EXPECT_EQ(d.decoded_pixels, d.lit_pixels);
}

TEST(GrayDecode, RefusesCodesBeyondTheProjectorAndAmbiguousBits) {
    // Patterns of a 128-wide projector decoded as a 100-wide one (the same 7 bits): columns 100..127
    // are codes no 100-wide projector shows.
    std::vector<cv::Mat> camera = film(render_gray_patterns({128, 60}), {256, 120}, cv::Rect());
    const GrayLayout layout = gray_layout({100, 60});
    // An ambiguous bit: pattern equal to its inverse in one pixel.
    camera[4].at<std::uint8_t>(50, 10) = camera[5].at<std::uint8_t>(50, 10);
    const DecodedPixels d = decode_gray(camera, layout);
    EXPECT_FALSE(d.decoded(10, 50));
    EXPECT_TRUE(d.decoded(12, 50));
    for (int x = 0; x < 256; ++x) EXPECT_EQ(d.decoded(x, 30), x < 200) << x;
}

TEST(GrayDecode, BadCapturesAreRefusedNamingTheLimit) {
    const GrayLayout layout = gray_layout({16, 16});
    std::vector<cv::Mat> images = render_gray_patterns({16, 16});
    images.pop_back();
    try {
        (void)decode_gray(images, layout);
        FAIL() << "no throw";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("must hold 18 images"), std::string::npos) << e.what();
    }
    images = render_gray_patterns({16, 16});
    images[3] = cv::Mat(8, 8, CV_8UC1, cv::Scalar(0));
    EXPECT_THROW((void)decode_gray(images, layout), std::invalid_argument);
}

// Decoded pixels that follow a known homography (rounded to whole projector pixels, as decoding
// gives them), 10 % of them with random wrong codes: the corner's projector position is H(corner).
TEST(LocalHomography, RecoversTheCornerThroughRoundedAndWrongCodes) {
    const cv::Matx33d h(0.8, 0.1, 30.0, -0.05, 0.85, 40.0, 1e-4, -5e-5, 1.0);
    DecodedPixels d;
    d.projector = cv::Mat(200, 200, CV_32SC2, cv::Scalar(-1, -1));
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int y = 0; y < 200; ++y) {
        for (int x = 0; x < 200; ++x) {
            const cv::Vec3d p = h * cv::Vec3d(x, y, 1.0);
            cv::Vec2i code(static_cast<int>(std::lround(p[0] / p[2])), static_cast<int>(std::lround(p[1] / p[2])));
            if (u(rng) < 0.1) code = cv::Vec2i(static_cast<int>(400 * u(rng)), static_cast<int>(400 * u(rng)));
            if (u(rng) < 0.3) code = cv::Vec2i(-1, -1);  // not decoded
            d.projector.at<cv::Vec2i>(y, x) = code;
        }
    }
    const std::vector<cv::Point2f> corners{{100.3f, 97.6f}, {60.8f, 140.2f}};
    const std::vector<ProjectorCorner> got = projector_corners(d, corners);
    ASSERT_EQ(got.size(), 2u);
    for (std::size_t i = 0; i < corners.size(); ++i) {
        const cv::Vec3d p = h * cv::Vec3d(corners[i].x, corners[i].y, 1.0);
        ASSERT_TRUE(got[i].valid);
        EXPECT_NEAR(got[i].position.x, p[0] / p[2], 0.05);
        EXPECT_NEAR(got[i].position.y, p[1] / p[2], 0.05);
        EXPECT_GT(got[i].inliers, got[i].pixels / 2);
    }
    // A corner with no decoded pixels around it has no projector position.
    const std::vector<ProjectorCorner> none =
        projector_corners(DecodedPixels{cv::Mat(200, 200, CV_32SC2, cv::Scalar(-1, -1))}, corners);
    EXPECT_FALSE(none[0].valid);
    EXPECT_THROW((void)projector_corners(d, corners, HomographyOptions{1, 50, 1.0}), std::invalid_argument);
}

}  // namespace
}  // namespace mogao::procam
