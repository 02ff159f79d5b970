// SPDX-License-Identifier: Apache-2.0
// A projector's white where the camera clips it, from the same projector at grey (camera_clipping.h).
#include "appliance/autocal/camera_clipping.h"

#include <algorithm>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace mogao::autocal {
namespace {

// The ratio's samples: the white well above the camera's noise and below clipping, the grey above the noise.
constexpr float kRatioWhiteMin = 0.2f;
constexpr float kRatioWhiteMax = 0.9f;
constexpr float kRatioGreyMin = 0.02f;
constexpr std::size_t kMinRatioSamples = 64;
// The grey is averaged over this window (camera pixels), over clipped pixels only: the lit side of an edge.
constexpr int kGreyWindow = 5;

double median(std::vector<float>& v) {
    std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
    return v[v.size() / 2];
}

}  // namespace

DeclippedWhite declip_white(const cv::Mat1f& white, const cv::Mat1f& grey, const cv::Mat1f& black) {
    DeclippedWhite out;
    cv::subtract(white, black, out.light);
    cv::Mat1f grey_light;
    cv::subtract(grey, black, grey_light);
    std::vector<float> ratios;
    cv::Mat1f clipped(white.size(), 0.0f);
    for (int y = 0; y < white.rows; ++y) {
        for (int x = 0; x < white.cols; ++x) {
            if (grey(y, x) >= kCameraClipLevel) ++out.grey_clipped_pixels;
            if (white(y, x) >= kCameraClipLevel) {
                clipped(y, x) = 1.0f;
                ++out.clipped_pixels;
            } else if (white(y, x) >= kRatioWhiteMin && white(y, x) <= kRatioWhiteMax &&
                       grey_light(y, x) >= kRatioGreyMin) {
                ratios.push_back(out.light(y, x) / grey_light(y, x));
            }
        }
    }
    if (out.clipped_pixels == 0 || ratios.size() < kMinRatioSamples) return out;
    out.ratio = median(ratios);
    cv::Mat1f grey_sum;
    cv::Mat1f count;
    const cv::Size window(kGreyWindow, kGreyWindow);
    cv::boxFilter(grey_light.mul(clipped), grey_sum, CV_32F, window, cv::Point(-1, -1), false);
    cv::boxFilter(clipped, count, CV_32F, window, cv::Point(-1, -1), false);
    std::vector<float> levels;
    levels.reserve(static_cast<std::size_t>(out.clipped_pixels));
    for (int y = 0; y < white.rows; ++y) {
        for (int x = 0; x < white.cols; ++x) {
            if (clipped(y, x) == 0.0f) continue;
            // Smoothed only where the whole window is clipped: toward an edge the window would reach further in,
            // where the light is higher than at this pixel.
            const bool inside = count(y, x) >= static_cast<float>(kGreyWindow * kGreyWindow);
            const float grey_here = inside ? grey_sum(y, x) / count(y, x) : grey_light(y, x);
            const float estimate = static_cast<float>(out.ratio) * grey_here;
            out.light(y, x) = std::max(out.light(y, x), estimate);
            levels.push_back(out.light(y, x) + black(y, x));
        }
    }
    out.overdrive = std::max(1.0, median(levels));
    return out;
}

}  // namespace mogao::autocal
