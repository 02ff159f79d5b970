// SPDX-License-Identifier: Apache-2.0
#include "appliance/decode/last_good_frame.h"

#include <gtest/gtest.h>

#include "common/image_compare.h"

namespace mogao {
namespace {

Rgb8Image gradient(ImageSize size, int phase) {
    Rgb8Image image(size);
    for (int y = 0; y < size.height; ++y) {
        for (int x = 0; x < size.width; ++x) {
            std::uint8_t* p = image.at(x, y);
            p[0] = static_cast<std::uint8_t>((x * 255) / size.width);
            p[1] = static_cast<std::uint8_t>((y * 255) / size.height);
            p[2] = static_cast<std::uint8_t>((phase * 40 + x + y) % 256);
        }
    }
    return image;
}

LinkFrame encoded(std::uint64_t request_id, const Rgb8Image& image) {
    JpegEncoder encoder;
    LinkFrame f;
    f.request_id = request_id;
    f.frame_id = request_id;
    f.size = image.size;
    f.pose.yaw_deg = static_cast<double>(request_id);
    f.times.request_ns = 1000;
    f.times.receive_ns = 2000;
    f.jpeg = encoder.encode(image, 90);
    return f;
}

TEST(LastGoodFrame, AcceptsADecodableFrame) {
    LastGoodFrame last;
    EXPECT_EQ(last.current(), nullptr);
    const Rgb8Image source = gradient({64, 48}, 1);
    const LinkFrame f = encoded(7, source);
    ASSERT_EQ(last.accept(f), "");
    ASSERT_NE(last.current(), nullptr);
    EXPECT_EQ(last.current()->request_id, 7u);
    EXPECT_EQ(last.current()->image.size, (ImageSize{64, 48}));
    EXPECT_EQ(last.current()->jpeg_bytes, f.jpeg.size());
    EXPECT_EQ(last.current()->times.receive_ns, 2000);
    EXPECT_DOUBLE_EQ(last.current()->pose.yaw_deg, 7.0);
    EXPECT_GT(psnr(last.current()->image, source), 30.0);
    EXPECT_EQ(last.accepted(), 1u);
}

// The rule the outputs rely on: a frame that cannot be decoded completely is dropped and the
// previous frame stays current, pixel for pixel.
TEST(LastGoodFrame, KeepsTheLastGoodFrameWhenACorruptJpegArrives) {
    LastGoodFrame last;
    ASSERT_EQ(last.accept(encoded(3, gradient({64, 48}, 1))), "");
    const Rgb8Image before = last.current()->image;

    LinkFrame truncated = encoded(4, gradient({64, 48}, 2));
    truncated.jpeg.resize(truncated.jpeg.size() / 2);  // premature end of data
    LinkFrame garbage = encoded(5, gradient({64, 48}, 3));
    for (std::size_t i = 0; i < garbage.jpeg.size(); ++i) garbage.jpeg[i] = static_cast<std::uint8_t>(i * 31);
    LinkFrame no_eoi = encoded(6, gradient({64, 48}, 4));
    no_eoi.jpeg.resize(no_eoi.jpeg.size() - 40);  // scan data cut short
    LinkFrame empty = encoded(7, gradient({64, 48}, 5));
    empty.jpeg.clear();

    for (const LinkFrame* bad : {&truncated, &garbage, &no_eoi, &empty}) {
        const std::string why = last.accept(*bad);
        EXPECT_NE(why, "") << "request " << bad->request_id << " was accepted";
        EXPECT_NE(why.find("request " + std::to_string(bad->request_id)), std::string::npos) << why;
        ASSERT_NE(last.current(), nullptr);
        EXPECT_EQ(last.current()->request_id, 3u);
        EXPECT_EQ(last.current()->image.pixels, before.pixels) << "the frame on screen changed";
    }
    EXPECT_EQ(last.rejected(), 4u);

    // The next good frame replaces it.
    ASSERT_EQ(last.accept(encoded(8, gradient({64, 48}, 6))), "");
    EXPECT_EQ(last.current()->request_id, 8u);
}

TEST(LastGoodFrame, RefusesAFrameWhoseSizeDiffersFromTheDeclaredOne) {
    LastGoodFrame last;
    LinkFrame f = encoded(1, gradient({64, 48}, 1));
    f.size = {48, 64};
    const std::string why = last.accept(f);
    EXPECT_NE(why.find("decoded 64x48 but the farm declared 48x64"), std::string::npos) << why;
    EXPECT_EQ(last.current(), nullptr);
}

TEST(LastGoodFrame, NeverGoesBackToAnOlderRequest) {
    LastGoodFrame last;
    ASSERT_EQ(last.accept(encoded(10, gradient({32, 32}, 1))), "");
    EXPECT_NE(last.accept(encoded(9, gradient({32, 32}, 2))).find("not newer than request 10"), std::string::npos);
    EXPECT_NE(last.accept(encoded(10, gradient({32, 32}, 3))), "");
    EXPECT_EQ(last.current()->request_id, 10u);
}

}  // namespace
}  // namespace mogao
