// SPDX-License-Identifier: Apache-2.0
// One capture folder of the bench calibration: graycode_00.png .. graycode_NN.png, the camera's
// 8-bit images of the patterns of gray_decode.h in their order (the pattern pairs, then white, then
// black; 42 files for a 1024x768 projector). The naming is that of kamino410/procam-calibration and
// of OpenCV's structured_light samples.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "appliance/procam/gray_decode.h"

namespace mogao::procam {

// The file name of image `index` (graycode_07.png).
[[nodiscard]] std::string capture_file_name(int index);

// Reads the layout's image_count() images of `folder` as CV_8U grey (colour PNGs: their green,
// which is grey's own value in a grey PNG). Throws ProcamError naming the file: missing or
// unreadable (libpng's reason), a size different from graycode_00.png's (both sizes named), a
// camera outside 16..16384 pixels per side, or an extra graycode_NN.png past the expected count
// (the patterns were made for another projector size).
[[nodiscard]] std::vector<cv::Mat> load_capture_folder(const std::filesystem::path& folder, const GrayLayout& layout);

}  // namespace mogao::procam
