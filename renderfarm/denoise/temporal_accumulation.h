// SPDX-License-Identifier: Apache-2.0
// Temporal accumulation of moving frames by reprojection: the temporal half of spatiotemporal
// variance-guided filtering (Schied et al., "Spatiotemporal Variance-Guided Filtering: Real-Time
// Reconstruction for Path-Traced Global Illumination", HPG 2017, §4.1). The scene is static, so a
// surface point that a pixel sees now was seen by the previous frame at a known image position: its
// camera projects the point there (renderfarm/trace/camera.h's project_to_image, evaluated in float
// from per-frame tables: renderfarm/trace/frame_projection.h, within 1e-3 px of the exact one). Each
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
//   C = the pixel's radiance demodulated: divided by max(albedo, 1e-3) per channel (the first
//   hit's albedo guide; SVGF §4: the history holds untextured illumination, so texture, which each
//   frame's guides give exactly at every pixel, is never resampled from earlier frames);
//   H, n = the accepted taps' weighted mean of the previous illumination and history length (with
//   sharp_history, H is the 4x4 Catmull-Rom interpolation instead where all four are accepted,
//   clamped to their range);
//   out = ((1 − a) H + a C) ⊙ max(albedo, 1e-3),  a = max(alpha, 1 / (n + 1)),  new length n + 1;
//   no accepted tap (disoccluded, or outside the previous image): out = the pixel's own radiance,
//   length 1.
// a = 1/(n+1) makes the first frames of a point an exact running mean; alpha (SVGF: 0.2) keeps
// the average exponential after that, so a change (a light switched, a tap wrongly accepted) fades
// within about 1/alpha frames. Bias: the average lags by up to 1/alpha frames: glossy highlights,
// which move with the eye, smear; everything the radiance cache or the path tracer estimates as
// view-independent does not.
//
// A sparse frame (view_request.h, ViewRequest::shading_one_in) leaves most surface pixels unshaded
// (kUnshadedRadiance in red): such a pixel takes the history H alone, its length unchanged; one the
// history does not cover is filled from the frame's own pixels around it on the same surface, with
// length 0 so that its first shaded sample replaces the fill. A pixel is shaded once every
// shading_one_in frames, so a shaded pixel weighs its sample as alpha would over that many frames
// (accumulate()): the lag stays, the average holds fewer samples (more noise for the spatial
// filter), and each frame traces a fraction of the paths. This is checkerboard
// rendering's reconstruction from temporal history, with the rotating pattern as its refresh.
//
// The history also keeps each pixel's luminance moments (SVGF §4.2, the temporal variance): m1 and
// m2, the running means of l and l² over its samples, l the demodulated luminance (Rec. 709 weights),
// blended with the same weights a as the illumination and resampled bilinearly with its accepted taps
// (never by Catmull-Rom, which would give m1 another resampling than m2); and f, the variance of the
// blended value over one sample's: f = 1 for a first sample, f' = (1 − a)² f_H + a² at a blend, with
// f_H = Σ w_k² f_k / (Σ w_k)² over the bilinear taps w_k (a resampled value averages its neighbours'
// noise; the variance of a weighted mean of independent values is Σ w_k² σ_k² / (Σ w_k)²), also where
// the illumination is sharpened by Catmull-Rom (the cubic's own Σ w² in f was tried: it read farther
// from the blend's measured error in the panning test than the bilinear weights do). A pixel whose
// history holds at least kMinMomentsFrames frames gets the variance of its blended luminance
//   Var(l̄) = max(0, m2 − m1²) · f.
// SVGF feeds the samples' σ² = m2 − m1² itself; this is what is left of it in the frame the filter
// sees. Two biases of opposite sign under motion: neighbouring pixels that shared earlier samples
// are taken as independent (f reads low), and resampling widens m2 − m1² by the spread of the
// neighbours' means (reads high); the TemporalAccumulation tests print the estimate against the
// blend's measured error, still and panning. A shorter history gets −1 (unknown: the filter
// estimates it spatially, as SVGF does for short histories). An unshaded pixel resamples its
// moments and adds none; a filled hole's are those of its fill (l̄, l̄², 1), its variance unknown.
// A non-finite spread (a NaN sample, a square past float's range) starts the pixel again: its
// history's illumination, moments and length 0, so that its next shaded sample replaces it, and −1
// until its history is long again (the frame that had it outputs it, as before).
//
// Frames may change size between calls (the frame-time target scales them): the history keeps its
// own size and camera. Pure CPU code, no GL, no Embree; rows run on every core.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/image.h"
#include "renderfarm/trace/camera.h"
#include "renderfarm/trace/frame_projection.h"
#include "renderfarm/trace/guide_buffers.h"

namespace mogao {

struct TemporalParams {
    float alpha = 0.2f;             // least weight of the current frame, (0, 1]; 1 = no accumulation
    float plane_tolerance = 0.01f;  // of the pixel's depth, > 0
    float normal_min_cos = 0.9f;    // in [-1, 1]
    // The history interpolated by Catmull-Rom where the 2x2 bilinear taps are all the same surface
    // (bilinear elsewhere): sharp where the view moves by fractions of a pixel; off: bilinear.
    bool sharp_history = true;
};

// Throws std::invalid_argument naming the field and its limit.
void check_temporal_params(const TemporalParams& params);

// What one accumulate() did, for statistics.
struct TemporalStats {
    std::size_t surface_pixels = 0;  // pixels that hit a surface
    std::size_t reprojected = 0;     // ... of which blended with the history
    std::size_t unshaded = 0;        // ... of which a sparse frame did not shade (kUnshadedRadiance)
    std::size_t filled = 0;          // ... of those, no history covered: filled from their neighbours
};

class TemporalHistory {
public:
    // Blends `current` (linear radiance, the size of `guides`, seen by `camera` whose size is the
    // frame's) with the history, keeps the result as the new history and returns it. Throws
    // std::invalid_argument for a size mismatch or bad params (naming the field and its limit).
    // `shading_one_in`: the frame is sparse (ViewRequest::shading_one_in, >= 1), so each pixel is
    // shaded once in that many frames and a shaded pixel's least weight is 1 − (1 − alpha)^N, the
    // weight alpha would have given its new samples over N frames: the history lags by as many
    // frames as in a full frame's.
    RgbFloatImage accumulate(const RgbFloatImage& current, const GuideBuffers& guides, const CameraSetup& camera,
                             const TemporalParams& params, TemporalStats* stats = nullptr, int shading_one_in = 1);

    // After accumulate(): the variance of each pixel's blended demodulated luminance (W*H of the
    // frame, squared illumination units; 0 for sky, −1 where the history is shorter than
    // kMinMomentsFrames, which a non-finite spread restarts), as AtrousDenoiser::run takes it. Empty before the first
    // frame.
    [[nodiscard]] const std::vector<float>& luminance_variance() const { return luminance_variance_; }
    static constexpr float kMinMomentsFrames = 4.0f;  // SVGF §4.2: shorter histories are estimated spatially

    // Forgets everything: the next frame starts its own history.
    void clear();
    [[nodiscard]] bool empty() const { return illumination_.empty(); }

private:
    // One accumulate() call's inputs and outputs.
    struct Pass {
        const RgbFloatImage& current;
        const GuideBuffers& guides;
        PixelCentreRays rays;        // the current frame's
        FrameProjection to_history;  // into the previous frame's image (its camera_)
        const TemporalParams& params;
        float alpha;  // a shaded pixel's least weight: params.alpha over shading_one_in frames
        RgbFloatImage& out;
        std::vector<float>& illumination;
        std::vector<float>& position;
        std::vector<float>& plane;
        std::vector<float>& length;
        std::vector<float>& moments;
        std::vector<float>& luminance_variance;
    };
    struct Moments {
        float m1 = 0.0f, m2 = 0.0f;  // running means of l and l² (above)
        float factor = 0.0f;         // f: the variance of the blend over one sample's (above)
    };
    void accumulate_rows(const Pass& f, int y0, int y1, TemporalStats& result) const;
    static std::size_t fill_holes(const Pass& f);
    static bool neighbour_fill(const Pass& f, std::size_t i, int radius, Eigen::Vector3f& value);
    static void set_pixel(const Pass& f, std::size_t i, const Eigen::Vector3f& value);
    void sharpen(float fx, float fy, Eigen::Vector3f& value) const;
    // The history at the previous image's position (px, py) (project_row's) for the point `position`.
    [[nodiscard]] bool gather(const Pass& f, const Eigen::Vector3f& position, const Eigen::Vector3f& normal,
                              float depth, float px, float py, Eigen::Vector3f& value, float& length,
                              Moments& moments) const;
    static void set_moments(const Pass& f, std::size_t i, Moments m, float length);

    CameraSetup camera_;
    std::vector<float> illumination_;  // W*H*3 the previous output demodulated (radiance / albedo)
    std::vector<float> plane_;         // W*H n·P of each pixel's hit: its tangent plane's offset, metres
    std::vector<float> normal_;        // W*H*3 unit world normals
    std::vector<std::uint8_t> hit_;    // W*H
    std::vector<float> length_;        // W*H frames averaged
    std::vector<float> moments_;       // W*H*3 (m1, m2, f) of the luminance, see above
    // Scratch the next frame's history is written into (and each pixel's point), swapped with the
    // history after each frame: a frame of a stable size allocates and zero-fills nothing. Every
    // element is written by accumulate() before it is read.
    std::vector<float> next_illumination_;
    std::vector<float> next_plane_;
    std::vector<float> next_length_;
    std::vector<float> next_moments_;
    std::vector<float> luminance_variance_;  // W*H the current frame's, see luminance_variance()
    std::vector<float> position_;            // W*H*3 the current frame's points, world metres
};

}  // namespace mogao
