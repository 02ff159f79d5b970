// SPDX-License-Identifier: Apache-2.0
// A camera that clips a projector's white, and the lit edges (step 2 of autocal.h) found through it anyway.
//
// Why: the lit edges are the crossings of the local half level between the lit and the dark side
// (screen_geometry.cpp, find_edges). Where the camera clips the lit side, that side reads full scale
// instead of its light, the half level lies below the true one, and the crossing moves outward (for an edge
// blurred by a Gaussian of sigma px and a white `overdrive` times full scale, by sigma Phi^-1(1 - 1 / (2
// overdrive)) px; 0.4 px at overdrive 1.2 and sigma 2). The camera's pose moves with the crossings: on a
// gain screen filmed brighter than its rig sets the camera, the screen heights' check refused a calibration
// for a few millimetres of clipped top edge (docs/calibration.md, "Camera saturation").
//
// How: each projector's white is shown again at `kLitGreySignal`, which the camera does not clip unless the
// white is several times full scale. A projector's light at any signal is its white's times one ratio over
// its whole image (its response at that signal; the screen's gain, its thrown-back light and the camera's
// vignetting scale both images alike), so the ratio white / grey is measured where neither is clipped (the
// edges' slopes, the dim parts) and, where the white is clipped, its light is the grey's (smoothed over the
// clipped pixels only, for the grey's lower signal-to-noise) times that ratio, where that exceeds the clipped
// value by three of its own sigmas (a white just at full scale keeps its own level). The crossings are still found
// on the white image, at its full signal-to-noise: only their lit side's level comes from the grey.
// Limits: a white above about three times full scale (kMaxWhiteOverdrive), or the grey clipped as well, is
// refused by the caller, naming the exposure.
#pragma once

#include <opencv2/core.hpp>

namespace mogao::autocal {

// The signal of each projector's second image for the lit edges (a grey, the same on every channel).
inline constexpr float kLitGreySignal = 0.5f;

// A camera value at or above this (the camera's image is in [0, 1]) is taken as clipped; below 1 for a codec
// that rounds full scale down by a code or two.
inline constexpr float kCameraClipLevel = 0.98f;

// Refused above this white (median over its clipped pixels, in units of full scale). The phase patterns
// (phase_shift.h) leave each pixel's clipped images out and need 3 of their 8 left: a sinusoid of full modulation
// peaking at W times full scale clips on an arc of half-width acos(2 / W - 1), which holds at most 5 of 8
// images 45 degrees apart while W < 3.24. Past it a pixel keeps its Gray-code position (not refined, with that
// block's larger sigma). Measured on realistic-screen at half scale (mean / p95 px): 0.097 / 0.162 unclipped
// (exposure 0.7), 0.111 / 0.171 at exposure 1.8 (median 2.2), 0.132 / 0.188 at 2.4 (median about 2.5), 0.120 /
// 0.185 at 3.0 (median about 3.1, refused); at 4.0 its grey clips too.
inline constexpr double kMaxWhiteOverdrive = 3.0;
// Refused where the grey clips on more than this share of the white's clipped pixels, plus this many (noise).
inline constexpr double kMaxGreyClippedShare = 0.01;
inline constexpr int kMaxGreyClippedPixels = 16;

struct DeclippedWhite {
    cv::Mat1f light;              // the white minus black, its clipped pixels replaced by grey x ratio
    int clipped_pixels = 0;       // the white's pixels at or above kCameraClipLevel
    int grey_clipped_pixels = 0;  // the grey's
    double ratio = 0.0;           // white / grey where neither clips (0: too few such pixels, nothing replaced)
    double overdrive = 1.0;       // median over the clipped pixels of the white's light / full scale (>= 1)
};

// `white` and `grey`: the camera's images (CV_32F, [0, 1]) of one projector at full white and at
// kLitGreySignal, the others black; `black`: every projector black; all the same size. Pure.
[[nodiscard]] DeclippedWhite declip_white(const cv::Mat1f& white, const cv::Mat1f& grey, const cv::Mat1f& black);

}  // namespace mogao::autocal
