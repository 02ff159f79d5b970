// SPDX-License-Identifier: Apache-2.0
// A projector's white where the camera clips it, from the same projector at grey (camera_clipping.h).
#include "appliance/autocal/camera_clipping.h"

#include <algorithm>
#include <cmath>
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
// A clipped pixel's light is replaced only where the grey's estimate exceeds it by this many of the estimate's
// own sigmas: a white just at full scale is nearly its own light, and the grey's noise, scaled by the ratio
// (about 4.6 at gamma 2.2) and kept only where it is above, would raise the lit side's level and move the edges.
constexpr float kReplaceSigmas = 3.0f;

double median(std::vector<float>& v) {
    std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
    return v[v.size() / 2];
}

// The grey's noise sigma over the white's clipped pixels (the lit side, where light varies slowly): from
// horizontal neighbours' differences, 1.4826 MAD / sqrt(2). 0 where fewer than kMinRatioSamples pairs.
float clipped_grey_noise(const cv::Mat1f& grey, const cv::Mat1f& clipped) {
    std::vector<float> diffs;
    for (int y = 0; y < grey.rows; ++y) {
        for (int x = 0; x + 1 < grey.cols; ++x) {
            if (clipped(y, x) != 0.0f && clipped(y, x + 1) != 0.0f)
                diffs.push_back(std::abs(grey(y, x + 1) - grey(y, x)));
        }
    }
    if (diffs.size() < kMinRatioSamples) return 0.0f;
    return static_cast<float>(1.4826 * median(diffs) / std::sqrt(2.0));
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
    const float grey_noise = clipped_grey_noise(grey, clipped);
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
            const float sigma = static_cast<float>(out.ratio) * grey_noise / (inside ? kGreyWindow : 1.0f);
            if (estimate > out.light(y, x) + kReplaceSigmas * sigma) out.light(y, x) = estimate;
            levels.push_back(out.light(y, x) + black(y, x));
        }
    }
    out.overdrive = std::max(1.0, median(levels));
    return out;
}

}  // namespace mogao::autocal
