// SPDX-License-Identifier: Apache-2.0
// The virtual rig as the calibration's input, and the calibration measured against the rig's
// ground truth (never against the calibration's own prediction): docs/calibration.md. LABORATORY code
// (.ci/check-shipped-links); the prior a rig file gives (site_prior.h) is not.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <vector>

#include "appliance/autocal/autocal.h"
#include "appliance/autocal/indirect_light.h"
#include "appliance/autocal/site_prior.h"
#include "appliance/rig/virtual_rig.h"

namespace mogao::autocal {

// Shows patterns on the virtual rig and returns its camera image (a new noise seed per image).
// Keeps the wall time spent simulating the camera, so that a job can report the calibration's own
// compute time apart from the rig's. The camera's timing (rig::RigCamera::straddle): the first frame
// after the shown signals change holds that share of the previous signals' light, unless `drop_frames`
// (>= 0) frames are dropped after each change, as the site's camera source does (a dropped frame is not
// simulated and takes no noise seed).
class RigPatternSource : public PatternSource {
public:
    explicit RigPatternSource(const rig::VirtualRig& rig, int drop_frames = 0)
        : sim_(rig), base_exposure_(rig.camera.exposure), drop_frames_(drop_frames) {}
    [[nodiscard]] cv::Mat1f show(const std::vector<cv::Mat>& signals) override;
    [[nodiscard]] double simulate_s() const { return simulate_s_; }  // seconds inside show()
    [[nodiscard]] bool exposure_locked() const override { return !sim_.rig().camera.auto_exposure; }
    void set_relative_exposure(double factor) override { sim_.set_exposure(base_exposure_ * factor); }
    [[nodiscard]] bool lossy_frames() const override { return sim_.rig().camera.mjpeg_quality > 0; }
    [[nodiscard]] const rig::CameraSimulator& simulator() const { return sim_; }

private:
    rig::CameraSimulator sim_;
    double base_exposure_ = 1.0;
    int drop_frames_ = 0;
    std::vector<cv::Mat> shown_;  // the signals on the projectors (copies; empty before the first show)
    std::uint64_t frame_ = 0;
    double simulate_s_ = 0.0;
};

struct GeometryError {
    int samples = 0;       // projector pixels that land on the screen and were measured
    int missing = 0;       // of those, pixels the calibration shows nothing on (NaN warp or blend 0)
    int outside = 0;       // of those, pixels showing content that belongs beyond this projector's image
    double mean_px = 0.0;  // distance in projector pixels between where the pixel lands and where its content belongs
    double p95_px = 0.0;
    double max_px = 0.0;
};

// Every `step`-th projector pixel (centres at +0.5): ground truth screen point of the pixel vs the
// screen point of the content the calibration shows there (sample_warp), as the distance in the
// same projector's pixels (ground-truth projection of the belonging point). Pixels with blend 0
// are not shown and not measured, except as `missing` when they land inside the screen by more
// than `margin_px` projector pixels of border distance.
[[nodiscard]] GeometryError measure_geometry(const rig::VirtualRig& rig, const ScreenCalibration& calibration,
                                             int step);

// The content grid the seam measurements walk: `columns` x `rows` content points (u, v) inset by `inset`
// of the frame on every side, row by row, each as the screen point showing it (columns, rows >= 2).
[[nodiscard]] std::vector<rig::ScreenPoint> seam_grid(const rig::VirtualRig& rig, double inset, int columns = 401,
                                                      int rows = 101);
// Point (column i, row j) of that grid, without building it (a pixel-dense grid of a wide rig holds millions).
[[nodiscard]] rig::ScreenPoint seam_grid_point(const rig::VirtualRig& rig, double inset, int columns, int rows, int i,
                                               int j);

// A seam grid fine enough that a line one projector pixel wide cannot fall between its points: as many
// columns as the projectors have pixels side by side (their widths summed, overlaps counted twice) and
// as many rows as the tallest has, each times `per_pixel`. A seam's maximum is only as good as its grid:
// the default 401 x 101 points are 8 to 16 projector pixels apart on a wide rig.
struct SeamGridSize {
    int columns = 401;
    int rows = 101;
};
[[nodiscard]] SeamGridSize pixel_dense_seam_grid(const rig::VirtualRig& rig, double per_pixel = 1.0);

// Projector k's output pixel (floor of the ground-truth projection, clamped to the output) that
// lights screen point `s`; nullopt where projector k does not reach it.
[[nodiscard]] std::optional<std::array<int, 2>> output_pixel(const rig::VirtualRig& rig, int k,
                                                             const ProjectorCalibration& pc, const rig::ScreenPoint& s);
// The same from the projection itself (an image position, pixel centres at +0.5): floor, clamped to the output.
[[nodiscard]] std::array<int, 2> output_pixel_at(const ProjectorCalibration& pc, const Eigen::Vector2d& position);

struct LuminanceError {
    int samples = 0;
    double max_deviation = 0.0;       // max |L / median - 1| over the screen (white content)
    double seam_max_deviation = 0.0;  // the same over points lit by two or more projectors
    rig::ScreenPoint seam_max_at;     // where the seam's maximum is (theta, h)
};

// The rig's true lens fall-off of projector `p` as a model's LensFalloff (virtual_rig.h's
// 1 - falloff rho^2 is the quadratic (1, 0, 0, -falloff, 0, -falloff) about the principal point;
// exact where rho^2 <= 2, which covers the image for lens shifts up to half the image).
[[nodiscard]] LensFalloff falloff_of(const rig::RigProjector& p);

// White content through the calibration onto the rig (ground truth projections, the rig's
// responses, brightness and lens fall-off, the screen's gain toward the rig's viewer and one bounce of its
// own light; black level left out: black-level compensation is a later step), on a grid of content points
// inset by `inset` of the frame on every side.
// `grid`: the seam grid's size (pixel_dense_seam_grid for a maximum that sees one-pixel lines).
// With `indirect`, white content is shown less the indirect light's field (indirect_light.h), as the outputs show it.
// `defocused`: each defocused projector's (RigProjector::blur_px > 0) light at a point is its pixels' spread by their
// aperture and the blur (projector_footprint.h), as the screen shows it; else each pixel's light is a sharp step.
[[nodiscard]] LuminanceError measure_luminance(const rig::VirtualRig& rig, const ScreenCalibration& calibration,
                                               double inset = 0.01, SeamGridSize grid = {},
                                               const IndirectLight* indirect = nullptr, bool defocused = false);

}  // namespace mogao::autocal
