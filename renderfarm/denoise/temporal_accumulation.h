// SPDX-License-Identifier: Apache-2.0
// Temporal accumulation of moving frames by reprojection: the temporal half of spatiotemporal
// variance-guided filtering (Schied et al., "Spatiotemporal Variance-Guided Filtering: Real-Time
// Reconstruction for Path-Traced Global Illumination", HPG 2017, §4.1). The scene is static, so a
// surface point that a pixel sees now was seen by the previous frame at a known image position: its
// camera projects the point there exactly (renderfarm/trace/camera.h, project_to_image). Each
// pixel blends the previous frame's value there with its own, an exponential moving average
// over the frames that saw the point, so a moving view keeps most of its samples; the edge-avoiding
// à-trous filter (atrous_filter.h) then works on a far less noisy frame.
//
// Per pixel p of the current frame (guides of guide_buffers.h; sky pixels pass through):
//   P  = eye + depth(p) · d(p), d the unit ray through p's centre (camera.h), world metres;
//   (x, y) = the previous camera's projection of P, continuous image position;
//   taps: the 2x2 previous pixels around (x − ½, y − ½) (pixel centres at +½), bilinear weights;
//   a tap is the same surface (disocclusion test, SVGF §4.1's geometric tests) when it hit a
//   surface, its normal n' has n·n' >= normal_min_cos, and P lies within plane_tolerance · depth(p)
//   of the tap's tangent plane: |n'·(P − P')| (robust at grazing angles, where neighbouring pixels'
//   depths differ by far more than the surface's own offset);
//   H, n = the accepted taps' weighted mean of the previous output and history length;
//   out = (1 − a) H + a C,  a = max(alpha, 1 / (n + 1)),  new length n + 1;
//   no accepted tap (disoccluded, or outside the previous image): out = C, length 1.
// a = 1/(n+1) makes the first frames of a point an exact running mean; alpha (SVGF: 0.2) keeps
// the average exponential after that, so a change (a light switched, a tap wrongly accepted) fades
// within about 1/alpha frames. Bias: the average lags by up to 1/alpha frames: glossy highlights,
// which move with the eye, smear; everything the radiance cache or the path tracer estimates as
// view-independent does not.
//
// Frames may change size between calls (the frame-time target scales them): the history keeps its
// own size and camera. Pure CPU code, no GL, no Embree; rows run on every core.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/image.h"
#include "renderfarm/trace/camera.h"
#include "renderfarm/trace/guide_buffers.h"

namespace mogao {

struct TemporalParams {
    float alpha = 0.2f;             // least weight of the current frame, (0, 1]; 1 = no accumulation
    float plane_tolerance = 0.01f;  // of the pixel's depth, > 0
    float normal_min_cos = 0.9f;    // in [-1, 1]
};

// Throws std::invalid_argument naming the field and its limit.
void check_temporal_params(const TemporalParams& params);

// What one accumulate() did, for statistics.
struct TemporalStats {
    std::size_t surface_pixels = 0;  // pixels that hit a surface
    std::size_t reprojected = 0;     // ... of which blended with the history
};

class TemporalHistory {
public:
    // Blends `current` (linear radiance, the size of `guides`, seen by `camera` whose size is the
    // frame's) with the history, keeps the result as the new history and returns it. Throws
    // std::invalid_argument for a size mismatch or bad params (naming the field and its limit).
    RgbFloatImage accumulate(const RgbFloatImage& current, const GuideBuffers& guides, const CameraSetup& camera,
                             const TemporalParams& params, TemporalStats* stats = nullptr);

    // Forgets everything: the next frame starts its own history.
    void clear();
    [[nodiscard]] bool empty() const { return radiance_.pixels.empty(); }

private:
    // One accumulate() call's inputs and outputs.
    struct Pass {
        const RgbFloatImage& current;
        const GuideBuffers& guides;
        const CameraSetup& camera;
        CylinderColumns columns;
        const TemporalParams& params;
        RgbFloatImage& out;
        std::vector<float>& position;
        std::vector<float>& length;
    };
    void accumulate_rows(const Pass& f, int y0, int y1, TemporalStats& counted) const;
    [[nodiscard]] bool gather(const Eigen::Vector3f& position, const Eigen::Vector3f& normal, float depth,
                              const TemporalParams& params, Eigen::Vector3f& value, float& length) const;

    CameraSetup camera_;
    RgbFloatImage radiance_;         // the previous output
    std::vector<float> position_;    // W*H*3 world metres of each pixel's hit
    std::vector<float> normal_;      // W*H*3 unit world normals
    std::vector<std::uint8_t> hit_;  // W*H
    std::vector<float> length_;      // W*H frames averaged
};

}  // namespace mogao
