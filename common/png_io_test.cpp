// SPDX-License-Identifier: Apache-2.0
#include "common/png_io.h"

#include <gtest/gtest.h>
#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "common/file_io.h"
#include "common/test_images.h"

namespace mogao {
namespace {

namespace fs = std::filesystem;

// A fresh directory per test, removed afterwards.
class ImageFiles : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() /
               ("mogao_encode_" + std::to_string(::getpid()) + "_" + info->test_suite_name() + "_" + info->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    // Writes a PNG of an arbitrary libpng format, for read_png's conversions.
    void write_raw_png(const fs::path& path, png_uint_32 format, int width, int height, const void* data,
                       const void* colormap = nullptr, png_uint_32 colormap_entries = 0) {
        png_image image{};
        image.version = PNG_IMAGE_VERSION;
        image.width = static_cast<png_uint_32>(width);
        image.height = static_cast<png_uint_32>(height);
        image.format = format;
        image.colormap_entries = colormap_entries;
        ASSERT_NE(png_image_write_to_file(&image, path.c_str(), 0, data, 0, colormap), 0) << image.message;
    }

    fs::path dir_;
};

void expect_same_pixels(const Rgb8Image& a, const Rgb8Image& b) {
    ASSERT_EQ(a.size, b.size);
    EXPECT_TRUE(a.pixels == b.pixels);
}

std::vector<std::uint8_t> bytes_of(const std::string& s) { return {s.begin(), s.end()}; }

TEST_F(ImageFiles, PngRoundTripIsBitExact) {
    const Rgb8Image image = test_images::noise({37, 23});
    write_png(dir_ / "frame.png", image);
    expect_same_pixels(read_png(dir_ / "frame.png"), image);
}

// The fast setting is still lossless; on a smooth image its file is larger (no row filters).
TEST_F(ImageFiles, AFastPngIsBitExactAndLargerOnASmoothImage) {
    const Rgb8Image image = test_images::gradient({256, 128});
    write_png(dir_ / "small.png", image);
    write_png(dir_ / "fast.png", image, PngCompression::fast);
    expect_same_pixels(read_png(dir_ / "fast.png"), image);
    EXPECT_GT(std::filesystem::file_size(dir_ / "fast.png"), std::filesystem::file_size(dir_ / "small.png"));
}

TEST_F(ImageFiles, PpmRoundTripIsBitExact) {
    const Rgb8Image image = test_images::noise({41, 19});
    write_ppm(dir_ / "frame.ppm", image);
    expect_same_pixels(read_ppm(dir_ / "frame.ppm"), image);
}

TEST_F(ImageFiles, WritesLeaveNoTemporaryFilesAndReplaceExistingFiles) {
    write_png(dir_ / "a.png", test_images::noise({8, 8}, 1));
    write_png(dir_ / "a.png", test_images::gradient({9, 7}));
    write_ppm(dir_ / "b.ppm", test_images::noise({8, 8}, 2));
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_)) names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    EXPECT_EQ(names, (std::vector<std::string>{"a.png", "b.ppm"}));
    expect_same_pixels(read_png(dir_ / "a.png"), test_images::gradient({9, 7}));
}

TEST_F(ImageFiles, WriteIntoMissingDirectoryNamesThePath) {
    const fs::path target = dir_ / "no_such_dir" / "frame.png";
    try {
        write_png(target, test_images::gradient({4, 4}));
        FAIL() << "wrote into a missing directory";
    } catch (const EncodeError& e) {
        EXPECT_NE(std::string(e.what()).find(target.string()), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("No such file or directory"), std::string::npos) << e.what();
    }
    EXPECT_THROW(write_ppm(target, test_images::gradient({4, 4})), EncodeError);
    // The generic writer keeps the errno code for callers that want it.
    try {
        write_file_atomically(target, std::vector<std::uint8_t>{1, 2, 3});
        FAIL();
    } catch (const std::system_error& e) {
        EXPECT_EQ(e.code(), std::errc::no_such_file_or_directory);
        EXPECT_NE(std::string(e.what()).find(target.string()), std::string::npos) << e.what();
    }
}

TEST_F(ImageFiles, ReadErrorsNameFileAndReason) {
    const fs::path missing = dir_ / "missing.png";
    try {
        (void)read_png(missing);
        FAIL();
    } catch (const DecodeError& e) {
        EXPECT_NE(std::string(e.what()).find(missing.string()), std::string::npos) << e.what();
    }
    const fs::path not_png = dir_ / "not.png";
    write_file_atomically(not_png, bytes_of("this is not a PNG file at all"));
    try {
        (void)read_png(not_png);
        FAIL();
    } catch (const DecodeError& e) {
        EXPECT_NE(std::string(e.what()).find(not_png.string()), std::string::npos) << e.what();
    }
    // A PNG cut in half: the header parses, the pixel data does not.
    write_png(dir_ / "full.png", test_images::noise({64, 64}));
    auto bytes = read_file_bytes(dir_ / "full.png");
    bytes.resize(bytes.size() / 2);
    write_file_atomically(dir_ / "half.png", bytes);
    EXPECT_THROW((void)read_png(dir_ / "half.png"), DecodeError);
}

TEST_F(ImageFiles, ReadPngConvertsGrayPaletteAndAlphaToRgb) {
    const std::vector<std::uint8_t> gray = {0, 100, 200, 255};
    write_raw_png(dir_ / "gray.png", PNG_FORMAT_GRAY, 2, 2, gray.data());
    const Rgb8Image g = read_png(dir_ / "gray.png");
    ASSERT_EQ(g.size, (ImageSize{2, 2}));
    for (int i = 0; i < 4; ++i) {
        EXPECT_EQ(g.pixels[i * 3 + 0], gray[i]);
        EXPECT_EQ(g.pixels[i * 3 + 1], gray[i]);
        EXPECT_EQ(g.pixels[i * 3 + 2], gray[i]);
    }

    const std::vector<std::uint8_t> palette = {255, 0, 0, 0, 0, 255, 10, 20, 30};
    const std::vector<std::uint8_t> indices = {2, 0, 1, 2};
    write_raw_png(dir_ / "palette.png", PNG_FORMAT_RGB_COLORMAP, 4, 1, indices.data(), palette.data(), 3);
    const Rgb8Image p = read_png(dir_ / "palette.png");
    EXPECT_EQ(p.pixels, (std::vector<std::uint8_t>{10, 20, 30, 255, 0, 0, 0, 0, 255, 10, 20, 30}));

    // Opaque pixels keep their colour; transparent ones become black.
    const std::vector<std::uint8_t> rgba = {10, 20, 30, 255, 200, 150, 100, 0};
    write_raw_png(dir_ / "alpha.png", PNG_FORMAT_RGBA, 2, 1, rgba.data());
    EXPECT_EQ(read_png(dir_ / "alpha.png").pixels, (std::vector<std::uint8_t>{10, 20, 30, 0, 0, 0}));
}

TEST_F(ImageFiles, ReadPpmAcceptsCommentsAndRefusesBadFiles) {
    write_file_atomically(dir_ / "c.ppm", bytes_of("P6\n# made by hand\n2 1 # two pixels\n255\nABCDEF"));
    EXPECT_EQ(read_ppm(dir_ / "c.ppm").pixels, bytes_of("ABCDEF"));

    const std::pair<const char*, std::string> bad[] = {
        {"ascii.ppm", "P3\n1 1\n255\n0 0 0\n"},
        {"short.ppm", "P6\n2 2\n255\nABCDEFGHI"},
        {"wide.ppm", "P6\n2 1\n65535\nABCDEFGHIJKL"},
        {"huge.ppm", "P6\n100000 100000\n255\nABC"},
        {"nosize.ppm", "P6\n\n"},
    };
    for (const auto& [name, content] : bad) {
        write_file_atomically(dir_ / name, bytes_of(content));
        try {
            (void)read_ppm(dir_ / name);
            ADD_FAILURE() << name << " accepted";
        } catch (const DecodeError& e) {
            EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
        }
    }
}

}  // namespace
}  // namespace mogao
