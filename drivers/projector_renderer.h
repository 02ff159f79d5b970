// SPDX-License-Identifier: Apache-2.0
// ProjectorRenderer: what an OutputBackend draws its outputs with, independent of the graphics API.
// It holds one content frame, the screen's indirect light field to take off it (set_indirect_light)
// and the calibration of each projector (warp map, blend mask, response LUT and black offset:
// common/projector_calibration.h), and draws one projector's picture into the target its backend
// has bound (OutputBackend::begin_frame). The formula it implements per output pixel is
// render_output's (appliance/warp/composite.h; docs/calibration.md); today's one
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

    // The screen's own light (interreflection of a concave screen), to be taken off the content
    // before the blend: a small content-space RGB field, linear light in content units (1 = the
    // light that content 1.0 makes; RgbFloatImage rows top first, width*height*3 values). Texel
    // (i, j) lies at the content's normalised ((i + 0.5) / W, (j + 0.5) / H), the pixel-centre
    // convention of sample_content (appliance/warp/composite.h); it is read bilinearly, texel
    // indices clamped to the edge (a 1x1 field is a constant), at the warp map's content
    // coordinate uv BEFORE the content transform: the field lies on the screen, in the
    // calibration's content coordinates, while the content frame is fetched at uv * scale +
    // offset. Per channel c: linear'_c = max(linear_c - indirect_c(uv), 0), then the blend as
    // render_output's formula (Bimber et al., "Compensating indirect scattering for immersive and
    // semi-immersive projection displays", IEEE VR 2006). An empty field (0 x 0, no values; the
    // default) subtracts nothing and draws exactly what a renderer without one draws. Shared by
    // all projectors; used by draw() from the next call on; meant to be called every frame (an
    // implementation reallocates its storage only when the size changes). EINVAL for a size with
    // one side 0, a size that does not match the values, or a value that is not finite or is < 0
    // (the message names the indirect light field, the texel and the limit); E2BIG for a side
    // beyond the implementation's maximum texture size. On an error the previous field stays in
    // use.
    [[nodiscard]] virtual Status set_indirect_light(const RgbFloatImage& field) = 0;
    // The field's size as last set successfully (0 x 0: none).
    [[nodiscard]] virtual ImageSize indirect_light_size() const = 0;

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
