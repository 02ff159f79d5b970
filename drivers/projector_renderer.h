// SPDX-License-Identifier: Apache-2.0
// ProjectorRenderer: what an OutputBackend draws its outputs with, independent of the graphics API.
// It holds one content frame and the calibration of each projector (warp map, blend mask, response
// LUT and black offset: common/projector_calibration.h), and draws one projector's picture into
// the target its backend has bound (OutputBackend::begin_frame). The formula it implements per
// output pixel is render_output's (appliance/warp/composite.h; docs/calibration.md); today's one
// implementation is the GLES 3 WarpBlendRenderer (drivers/egl/warp_blend_renderer.h), whose header
// gives the pixel-centre conventions and the precision.
//
// Threading: the backend's thread (for GL, its context current). Errors (common/result.h): EINVAL
// for bad arguments (sizes, lengths, indices, missing content, non-finite values; the message names
// the projector id and the map), E2BIG for sizes beyond the implementation's limit, EIO for failures
// of the graphics API.
#pragma once

#include <cstddef>

#include "common/image.h"
#include "common/projector_calibration.h"
#include "common/result.h"

namespace mogao {

// The late warp's content-space affine map (appliance/warp/late_warp.h): the warp map's content
// coordinates uv (normalised, [0, 1] across the content the calibration was made for) are fetched
// at uv * scale + offset of the current content frame, per axis. Identity (scale 1, offset 0) by
// default; with it the draw is exactly the untransformed one. Content texel indices clamp at the
// frame's edge.
struct ContentTransform {
    float scale_u = 1.0f, scale_v = 1.0f;
    float offset_u = 0.0f, offset_v = 0.0f;
    friend bool operator==(const ContentTransform&, const ContentTransform&) = default;
};

class ProjectorRenderer {
public:
    virtual ~ProjectorRenderer() = default;

    // The content frame: sRGB-encoded RGB8, rows top first (common/image.h). Once per frame,
    // before draw().
    [[nodiscard]] virtual Status set_content(const Rgb8Image& frame) = 0;

    // Validates and uploads one projector's calibration once; returns its index for draw().
    [[nodiscard]] virtual Result<std::size_t> add_projector(const ProjectorCalibration& calibration) = 0;
    // Replaces projector `index`'s calibration (a run-time calibration swap): the same checks as
    // add_projector; on any error the old calibration stays in use. EINVAL also for an index >=
    // projector_count().
    [[nodiscard]] virtual Status replace_projector(std::size_t index, const ProjectorCalibration& calibration) = 0;

    // Used by draw() from the next call on.
    virtual void set_content_transform(const ContentTransform& transform) = 0;
    [[nodiscard]] virtual const ContentTransform& content_transform() const = 0;

    [[nodiscard]] virtual std::size_t projector_count() const = 0;
    // Output size of projector `index` (< projector_count()), pixels.
    [[nodiscard]] virtual ImageSize output_size(std::size_t index) const = 0;

    // Draws projector `index` into the bound target, at the projector's output size.
    [[nodiscard]] virtual Status draw(std::size_t index) = 0;
    // The same picture resampled to fill a target of `target` pixels (an output whose mode differs
    // from the projector's calibrated output size: warp and blend are read at p * map.size / target).
    [[nodiscard]] virtual Status draw(std::size_t index, ImageSize target) = 0;
};

}  // namespace mogao
