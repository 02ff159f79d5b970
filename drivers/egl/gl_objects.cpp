// SPDX-License-Identifier: Apache-2.0
#include "drivers/egl/gl_objects.h"

#include <cstdio>
#include <string>
#include <vector>

namespace mogao {
namespace {

const char* gl_error_name(GLenum error) {
    switch (error) {
        case GL_INVALID_ENUM:
            return "GL_INVALID_ENUM";
        case GL_INVALID_VALUE:
            return "GL_INVALID_VALUE";
        case GL_INVALID_OPERATION:
            return "GL_INVALID_OPERATION";
        case GL_INVALID_FRAMEBUFFER_OPERATION:
            return "GL_INVALID_FRAMEBUFFER_OPERATION";
        case GL_OUT_OF_MEMORY:
            return "GL_OUT_OF_MEMORY";
        default:
            return "unknown GL error";
    }
}

Result<GlShader> compile(GLenum type, std::string_view source) {
    GlShader shader(glCreateShader(type));
    if (!shader.valid()) return make_error(EIO, "glCreateShader failed (no current GL context?)");
    const char* text = source.data();
    const auto length = static_cast<GLint>(source.size());
    glShaderSource(shader.get(), 1, &text, &length);
    glCompileShader(shader.get());
    GLint ok = GL_FALSE;
    glGetShaderiv(shader.get(), GL_COMPILE_STATUS, &ok);
    if (ok != GL_TRUE) {
        GLint log_length = 0;
        glGetShaderiv(shader.get(), GL_INFO_LOG_LENGTH, &log_length);
        std::string log(static_cast<std::size_t>(log_length > 0 ? log_length : 1), '\0');
        glGetShaderInfoLog(shader.get(), static_cast<GLsizei>(log.size()), nullptr, log.data());
        return make_error(EIO, std::string(type == GL_VERTEX_SHADER ? "vertex" : "fragment") +
                                   " shader does not compile: " + log.c_str());
    }
    return shader;
}

}  // namespace

Status gl_check(std::string_view what) {
    const GLenum first = glGetError();
    if (first == GL_NO_ERROR) return {};
    // Drain the rest so the next check reports only new errors (bounded: a lost context can
    // report errors forever).
    for (int i = 0; i < 16 && glGetError() != GL_NO_ERROR; ++i) {}
    return make_error(EIO, std::string(what) + ": " + gl_error_name(first));
}

GlTexture make_texture() {
    GLuint name = 0;
    glGenTextures(1, &name);
    return GlTexture(name);
}

GlRenderbuffer make_renderbuffer() {
    GLuint name = 0;
    glGenRenderbuffers(1, &name);
    return GlRenderbuffer(name);
}

GlFramebuffer make_framebuffer() {
    GLuint name = 0;
    glGenFramebuffers(1, &name);
    return GlFramebuffer(name);
}

Result<GlProgram> link_program(std::string_view vertex_source, std::string_view fragment_source) {
    auto vertex = compile(GL_VERTEX_SHADER, vertex_source);
    if (!vertex) return vertex.error();
    auto fragment = compile(GL_FRAGMENT_SHADER, fragment_source);
    if (!fragment) return fragment.error();
    GlProgram program(glCreateProgram());
    if (!program.valid()) return make_error(EIO, "glCreateProgram failed");
    glAttachShader(program.get(), vertex->get());
    glAttachShader(program.get(), fragment->get());
    glLinkProgram(program.get());
    GLint ok = GL_FALSE;
    glGetProgramiv(program.get(), GL_LINK_STATUS, &ok);
    if (ok != GL_TRUE) {
        GLint log_length = 0;
        glGetProgramiv(program.get(), GL_INFO_LOG_LENGTH, &log_length);
        std::string log(static_cast<std::size_t>(log_length > 0 ? log_length : 1), '\0');
        glGetProgramInfoLog(program.get(), static_cast<GLsizei>(log.size()), nullptr, log.data());
        return make_error(EIO, std::string("program does not link: ") + log.c_str());
    }
    // A linked program keeps working without its shaders; detach them so that deleting `vertex`
    // and `fragment` on return frees them now rather than with the program.
    glDetachShader(program.get(), vertex->get());
    glDetachShader(program.get(), fragment->get());
    return program;
}

Result<GlRenderTarget> make_render_target(ImageSize size) {
    GlRenderTarget target;
    target.size = size;
    target.color = make_renderbuffer();
    glBindRenderbuffer(GL_RENDERBUFFER, target.color.get());
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, size.width, size.height);
    target.fbo = make_framebuffer();
    glBindFramebuffer(GL_FRAMEBUFFER, target.fbo.get());
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, target.color.get());
    if (auto s = gl_check("make_render_target"); !s) return s.error();
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        return make_error(EIO, "RGBA8 framebuffer " + std::to_string(size.width) + "x" + std::to_string(size.height) +
                                   " is incomplete");
    }
    return target;
}

Status read_rgb8(ImageSize size, Rgb8Image& out, std::vector<std::uint8_t>& scratch) {
    const auto w = static_cast<std::size_t>(size.width);
    const auto h = static_cast<std::size_t>(size.height);
    scratch.resize(w * h * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    // GL_RGBA/GL_UNSIGNED_BYTE is the one read format every GLES 3 implementation accepts.
    glReadPixels(0, 0, size.width, size.height, GL_RGBA, GL_UNSIGNED_BYTE, scratch.data());
    if (auto s = gl_check("glReadPixels"); !s) return s;
    if (!(out.size == size)) out = Rgb8Image(size);
    for (std::size_t y = 0; y < h; ++y) {
        const std::uint8_t* src = scratch.data() + (h - 1 - y) * w * 4;
        std::uint8_t* dst = out.pixels.data() + y * w * 3;
        for (std::size_t x = 0; x < w; ++x) {
            dst[x * 3 + 0] = src[x * 4 + 0];
            dst[x * 3 + 1] = src[x * 4 + 1];
            dst[x * 3 + 2] = src[x * 4 + 2];
        }
    }
    return {};
}

}  // namespace mogao
