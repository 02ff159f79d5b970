// SPDX-License-Identifier: Apache-2.0
// The camera's timing against the projectors' flips (camera_timing.h).
#include "appliance/autocal/camera_timing.h"

#include <algorithm>

namespace mogao::autocal {

FrameStraddle measure_frame_straddle(PatternSource& source, const std::vector<ImageSize>& sizes, double min_contrast,
                                     int& captures) {
    std::vector<cv::Mat> white(sizes.size());
    for (std::size_t k = 0; k < sizes.size(); ++k) white[k] = cv::Mat1f(sizes[k].height, sizes[k].width, 1.0f);
    const std::vector<cv::Mat> black(sizes.size());
    (void)source.show(white);
    const cv::Mat1f lit = source.show(white).clone();  // the source may hand out a buffer it reuses
    const cv::Mat1f first_black = source.show(black).clone();
    const cv::Mat1f settled_black = source.show(black);
    captures += 4;
    std::vector<float> shares;
    for (int y = 0; y < lit.rows; ++y) {
        for (int x = 0; x < lit.cols; ++x) {
            const float contrast = lit(y, x) - settled_black(y, x);
            if (contrast > min_contrast) shares.push_back((first_black(y, x) - settled_black(y, x)) / contrast);
        }
    }
    FrameStraddle out;
    out.pixels = static_cast<int>(shares.size());
    if (shares.empty()) return out;
    const auto mid = shares.begin() + static_cast<long>(shares.size() / 2);
    std::nth_element(shares.begin(), mid, shares.end());
    out.share = *mid;
    return out;
}

}  // namespace mogao::autocal
