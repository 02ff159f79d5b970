// SPDX-License-Identifier: Apache-2.0
// RAII for GL object names (texture, renderbuffer, framebuffer, shader, program) and GL error
// checks. GL names belong to the context that made them: create, use and destroy each object with
// that context current on the calling thread (owners such as WarpBlendRenderer document this).
#pragma once

#include <GLES3/gl3.h>

#include <cstdint>
#include <string_view>
#include <vector>

#include "common/image.h"
#include "common/result.h"
#include "common/unique_handle.h"

namespace mogao {

// Drains glGetError(); EIO naming `what` and the first error (e.g. "GL_INVALID_VALUE") if any.
[[nodiscard]] Status gl_check(std::string_view what);

namespace gl_detail {
inline void delete_texture(GLuint n) { glDeleteTextures(1, &n); }
inline void delete_renderbuffer(GLuint n) { glDeleteRenderbuffers(1, &n); }
inline void delete_framebuffer(GLuint n) { glDeleteFramebuffers(1, &n); }
inline void delete_shader(GLuint n) { glDeleteShader(n); }
inline void delete_program(GLuint n) { glDeleteProgram(n); }
}  // namespace gl_detail

// Owns one GL name; 0 = empty. Move-only: a UniqueHandle (common/unique_handle.h) whose close()
// is the object's glDelete* (get(), valid(), release(), reset(name)).
template <void (*Delete)(GLuint)>
struct GlNameTraits {
    using Value = GLuint;
    static constexpr GLuint null() noexcept { return 0; }
    static void close(GLuint name) noexcept { Delete(name); }
};

template <void (*Delete)(GLuint)>
using GlObject = UniqueHandle<GlNameTraits<Delete>>;

using GlTexture = GlObject<&gl_detail::delete_texture>;
using GlRenderbuffer = GlObject<&gl_detail::delete_renderbuffer>;
using GlFramebuffer = GlObject<&gl_detail::delete_framebuffer>;
using GlShader = GlObject<&gl_detail::delete_shader>;
using GlProgram = GlObject<&gl_detail::delete_program>;

[[nodiscard]] GlTexture make_texture();
[[nodiscard]] GlRenderbuffer make_renderbuffer();
[[nodiscard]] GlFramebuffer make_framebuffer();

// Compiles a vertex + fragment shader pair and links them; EIO with the info log on failure.
[[nodiscard]] Result<GlProgram> link_program(std::string_view vertex_source, std::string_view fragment_source);

// An offscreen colour target: GL_RGBA8 renderbuffer attached to a framebuffer object.
struct GlRenderTarget {
    ImageSize size;
    GlRenderbuffer color;
    GlFramebuffer fbo;
};

// Makes a complete RGBA8 FBO of `size` (leaves it bound to GL_FRAMEBUFFER); EIO if incomplete.
[[nodiscard]] Result<GlRenderTarget> make_render_target(ImageSize size);

// Reads the framebuffer bound to GL_READ_FRAMEBUFFER, rectangle (0, 0, size), into `out` as RGB8
// with rows top first (GL row 0 is the bottom, so rows are flipped). `scratch` is reused RGBA
// memory so a per-frame readback does not allocate.
[[nodiscard]] Status read_rgb8(ImageSize size, Rgb8Image& out, std::vector<std::uint8_t>& scratch);

}  // namespace mogao
