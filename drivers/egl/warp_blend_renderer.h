// SPDX-License-Identifier: Apache-2.0
// WarpBlendRenderer: the GL layer of one projector output, the GLES 3 ProjectorRenderer
// (drivers/projector_renderer.h). It only uploads and draws: the content
// frame and the screen's indirect light field once per frame, each projector's calibration once,
// then one full-screen triangle per projector per frame (the shader is linked in variants: the
// general one and, for the common case of maps as large as the target, one that fetches each map
// once per pixel; each with and without beta and indirect light). The maths (fragment shader,
// GLSL ES 3.00), per output pixel (x, y):
//
//   p      = (x + 0.5, y + 0.5)                       output pixel centre, y down from the top row
//   uv     = bilinear(warp,  p * warp.size / output - 0.5)   in warp texel-centre coordinates
//   w      = bilinear(blend, p * blend.size / output - 0.5)
//   beta_c = bilinear(beta,  p * beta.size / output - 0.5)   per channel c; 0 when beta is empty
//   uv'    = uv * content_scale + content_offset  (per axis; identity unless set_content_transform)
//   linear = bilinear over the 4 content texels around uv' * content.size - 0.5, each texel
//            decoded sRGB -> linear first (on the CPU once per frame, uploaded as half floats,
//            GL_RGBA16F), so the filtering is in linear light; the texture unit filters (GL_LINEAR)
//   ind_c  = bilinear(indirect, uv * indirect.size - 0.5)   per channel c, at the warp's uv (not
//            uv': the field lies on the screen, in the calibration's content coordinates); 0 when
//            no field is set (set_indirect_light)
//   linear'_c = max(linear_c - ind_c, 0)            the screen's own light taken off the content
//            (Bimber et al., IEEE VR 2006)
//   out    = lut_c(clamp(linear'_c * w + beta_c, 0, 1))  per channel c; lut_c is piecewise linear
//            over its N entries at linear positions i / (N - 1). beta (the MPCDI beta map, black-level
//            offset in linear light) is added after the blend and is not scaled by the content, so
//            black content still shows beta (Majumder & Stevens, IEEE TVCG 10(2), 2004). This is
//            render_output's formula (appliance/warp/composite.h; docs/calibration.md)
//   out    = 0 (black) when a warp texel with non-zero bilinear weight is NaN/non-finite
//
// Bilinear lookups clamp texel indices to the map's edge (GL_CLAMP_TO_EDGE semantics); with
// map size == output size the warp, blend and beta are read exactly per pixel. The grid convention
// is sample_warp/sample_blend/sample_beta's (appliance/warp/warp_sampling.h), the indirect light's
// sample_content's (appliance/warp/composite.h). The warp, blend, beta, indirect light and LUT
// (32-bit floats, not filterable in core GLES 3.0) are filtered in the shader with
// texelFetch, so the geometry does not depend on a GPU's filtering precision; the content is
// filtered by the texture unit, a GPU's own precision (half-float texels, often 8-bit filter
// weights: docs/outputs.md, "Precision") within the 2-code tolerance the tests hold it to. Output
// values are written to an 8-bit UNORM target (x * 255 rounded to nearest).
//
// Targets: render() draws into the projector's own FBO (GL_RGBA8 renderbuffer) and reads it back;
// the headless backend never touches a default framebuffer (the surfaceless context has none).
// draw() draws into whatever framebuffer is bound to GL_DRAW_FRAMEBUFFER; the KMS backend binds 0
// with the output's GBM/EGL window surface current, then eglSwapBuffers + gbm lock + atomic flip.
// Output row 0 (top) is GL window row height-1, which is how both a window surface scans out and
// render() reads back (rows are flipped to top-first).
//
// Threading and lifetime: every call needs the GLES >= 3.0 context that was current at create()
// to be current on the calling thread, and the renderer must be destroyed with it still current.
// Errors: EINVAL for bad arguments (sizes, lengths, indices, missing content), E2BIG for sizes
// beyond GL_MAX_TEXTURE_SIZE, EIO for GL failures.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/image.h"
#include "common/projector_calibration.h"
#include "common/result.h"
#include "drivers/egl/gl_objects.h"
#include "drivers/projector_renderer.h"

namespace mogao {

class WarpBlendRenderer final : public ProjectorRenderer {
public:
    // Compiles and links the program; EIO if no GLES 3 context is current or the shader fails.
    [[nodiscard]] static Result<WarpBlendRenderer> create();

    // Uploads the content frame: sRGB-encoded RGB8, rows top first (common/image.h).
    // Call once per frame before draw()/render(); the texture is reallocated only on a size change.
    [[nodiscard]] Status set_content(const Rgb8Image& frame) override;

    // Validates and uploads one projector's warp map (RGBA32F: u, v and, when the blend mask has
    // the warp's size, the blend weight, so that one fetch reads both), blend mask (R32F), response LUT
    // ((N - 1) x 3 RG32F: each entry with its successor) and black offset (beta, RGBA32F; nothing
    // is uploaded or fetched when it is empty, 0 x 0), once. Returns the projector's index for
    // draw()/render(). EINVAL when a size is empty or does not match its data (beta:
    // width*height*3 values), the LUT channels differ in length or have < 2 entries, or a blend
    // weight, LUT entry or beta offset is not finite; the message names the projector id and the map.
    [[nodiscard]] Result<std::size_t> add_projector(const ProjectorCalibration& calibration) override;
    // Replaces projector `index`'s calibration (a run-time calibration swap, kiosk/calibration_reload.h):
    // the same checks and uploads as add_projector; on any error the old textures stay in use.
    // EINVAL also for an index >= projector_count().
    [[nodiscard]] Status replace_projector(std::size_t index, const ProjectorCalibration& calibration) override;

    // The screen's own light to take off the content before the blend (drivers/projector_renderer.h:
    // content space, linear light in content units, bilinear at texel centres, clamp to edge, at the
    // warp's uv before the content transform). Uploaded as RGBA32F, shared by all projectors, used
    // from the next draw; the texture is reallocated only on a size change, so a per-frame field
    // costs one small glTexSubImage2D. Empty (0 x 0) releases it, and the draws use the shader
    // variants without the lookup: the output is exactly that of a renderer without a field.
    // EINVAL (size with a 0 side, size/data mismatch, a non-finite or negative value: the message
    // names the indirect light field, the texel and the limit), E2BIG beyond GL_MAX_TEXTURE_SIZE,
    // EIO when the upload or (on the first field: the variants are linked then, so that screens
    // without one do not pay for them at create()) the shader fails; the previous field stays in
    // use on EINVAL and E2BIG.
    [[nodiscard]] Status set_indirect_light(const RgbFloatImage& field) override;
    [[nodiscard]] ImageSize indirect_light_size() const override { return indirect_size_; }

    // The late warp's content-space affine map (drivers/projector_renderer.h), applied to the warp
    // map's content coordinates before the content fetch.
    using ContentTransform = mogao::ContentTransform;
    void set_content_transform(const ContentTransform& transform) override { transform_ = transform; }
    [[nodiscard]] const ContentTransform& content_transform() const override { return transform_; }

    [[nodiscard]] std::size_t projector_count() const override { return projectors_.size(); }
    // Output size of projector `index` (< projector_count()).
    [[nodiscard]] ImageSize output_size(std::size_t index) const override { return projectors_.at(index).output; }

    // Draws projector `index` into the framebuffer bound to GL_DRAW_FRAMEBUFFER, viewport
    // (0, 0, output size). Leaves its program, textures (units 0-5) and viewport bound.
    [[nodiscard]] Status draw(std::size_t index) override;
    // The same picture resampled to fill a framebuffer of `target` pixels: for an output whose mode
    // differs from the projector's calibrated output size. In the formulas above `output` becomes
    // `target`, so warp and blend are read at p * map.size / target (bilinear); the calibration's
    // geometry scales with the mode (a projector shows its whole panel at any mode). EINVAL/E2BIG
    // for an empty target or one beyond GL_MAX_TEXTURE_SIZE.
    [[nodiscard]] Status draw(std::size_t index, ImageSize target) override;

    // Draws projector `index` into its own FBO and reads it back as RGB8, rows top first.
    [[nodiscard]] Result<Rgb8Image> render(std::size_t index);

private:
    struct Projector {
        ImageSize output;
        ImageSize warp_size;
        ImageSize blend_size;
        ImageSize beta_size;  // 0 x 0 when the calibration has no beta map
        GlTexture warp;
        GlTexture blend;
        GlTexture lut;
        GlTexture beta;         // empty (not valid) when the calibration has no beta map
        GlRenderTarget target;  // render()'s FBO, made on first use
    };

    WarpBlendRenderer() = default;
    [[nodiscard]] Result<Projector> make_projector(const ProjectorCalibration& calibration) const;  // checks, uploads
    [[nodiscard]] Status check_index(std::size_t index) const;

    // One linked variant of the fragment shader and its uniform locations.
    struct Program {
        GlProgram program;
        GLint output_size = -1;
        GLint warp_scale = -1;
        GLint blend_scale = -1;
        GLint beta_scale = -1;
        GLint content_scale = -1;
        GLint content_offset = -1;
    };
    // Linked variants: exact_maps (every map the target's size: one fetch for warp and blend, one
    // for beta; the same result as the general bilinear lookups), has_beta (the beta map is read
    // at all) and has_indirect (an indirect light field is set); without one the shader has no code
    // for it, rather than a uniform test that a software rasteriser would pay at every pixel.
    [[nodiscard]] static Result<Program> make_program(bool exact_maps, bool has_beta, bool has_indirect);
    static constexpr std::size_t program_index(bool exact_maps, bool has_beta, bool has_indirect) {
        return (exact_maps ? 4U : 0U) + (has_beta ? 2U : 0U) + (has_indirect ? 1U : 0U);
    }
    // Links the four variants with or without has_indirect (those with it on the first field).
    [[nodiscard]] Status link_programs(bool has_indirect);

    std::array<Program, 8> programs_;
    ContentTransform transform_;
    GLint max_texture_size_ = 0;
    GlTexture content_;
    GlTexture zero_rgb_;  // 1x1 zero RGBA32F, bound on unit 4 without beta and on unit 5 without indirect light
    ImageSize content_size_;
    GlTexture indirect_;       // set_indirect_light's field, RGBA32F; empty (not valid) when none
    ImageSize indirect_size_;  // 0 x 0 when none
    std::vector<Projector> projectors_;
    std::vector<std::uint8_t> readback_;         // RGBA scratch for render()
    std::vector<std::uint16_t> content_linear_;  // set_content's frame in linear light (RGBA half floats)
    std::vector<float> indirect_rgba_;           // set_indirect_light's field padded to RGBA
};

}  // namespace mogao
