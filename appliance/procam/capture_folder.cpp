// SPDX-License-Identifier: Apache-2.0
// Capture folders of the bench calibration (capture_folder.h).
#include "appliance/procam/capture_folder.h"

#include <cstdio>
#include <cstring>

#include "appliance/procam/procam_error.h"
#include "common/png_io.h"

namespace mogao::procam {

namespace {

std::string size_text(const cv::Size& s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

cv::Mat read_grey(const std::filesystem::path& file) {
    if (!std::filesystem::is_regular_file(file)) throw ProcamError(file.string() + ": missing");
    Rgb8Image rgb;
    try {
        rgb = read_png(file);
    } catch (const std::exception& e) {
        throw ProcamError(file.string() + ": cannot be read as PNG: " + e.what());
    }
    cv::Mat grey(rgb.size.height, rgb.size.width, CV_8UC1);
    for (int y = 0; y < rgb.size.height; ++y) {
        auto* out = grey.ptr<std::uint8_t>(y);
        for (int x = 0; x < rgb.size.width; ++x) out[x] = rgb.at(x, y)[1];
    }
    return grey;
}

}  // namespace

std::string capture_file_name(int index) {
    char name[32];
    std::snprintf(name, sizeof name, "graycode_%02d.png", index);
    return name;
}

std::vector<cv::Mat> load_capture_folder(const std::filesystem::path& folder, const GrayLayout& layout) {
    if (!std::filesystem::is_directory(folder)) throw ProcamError(folder.string() + ": not a folder");
    const std::filesystem::path extra = folder / capture_file_name(layout.image_count());
    if (std::filesystem::exists(extra)) {
        throw ProcamError(extra.string() + ": unexpected; a " + std::to_string(layout.projector.width) + "x" +
                          std::to_string(layout.projector.height) + " projector has " +
                          std::to_string(layout.image_count()) + " images (graycode_00.png .. " +
                          capture_file_name(layout.image_count() - 1) + "): is --projector-size the patterns' size?");
    }
    std::vector<cv::Mat> images;
    for (int i = 0; i < layout.image_count(); ++i) {
        const std::filesystem::path file = folder / capture_file_name(i);
        cv::Mat grey = read_grey(file);
        if (i == 0 && (grey.cols < 16 || grey.rows < 16 || grey.cols > 16384 || grey.rows > 16384)) {
            throw ProcamError(file.string() + ": camera image " + size_text(grey.size()) +
                              " is outside 16..16384 pixels per side");
        }
        if (i > 0 && grey.size() != images[0].size()) {
            throw ProcamError(file.string() + ": " + size_text(grey.size()) + " differs from " + capture_file_name(0) +
                              "'s " + size_text(images[0].size()));
        }
        images.push_back(std::move(grey));
    }
    return images;
}

}  // namespace mogao::procam
