// SPDX-License-Identifier: Apache-2.0
#include "drivers/egl/warp_blend_renderer.h"

#include <EGL/egl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

#include "common/srgb.h"

namespace mogao {
namespace {

// Uploaded warp texels below this mean "no content". NaN is the CPU-side marker, but GLSL ES 3.00
// does not require NaN support (isnan may be constant false), so NaN is replaced on upload by
// kNoContentUpload and valid uv are clamped to [-1, 2], which renders identically (clamp-to-edge)
// and keeps them far from the marker.
constexpr float kNoContentUpload = -1.0e30f;
constexpr std::uint16_t kHalfOne = 0x3C00;  // 1.0 as an IEEE half float

constexpr const char* kVertexShader = R"(#version 300 es
// One triangle covering the viewport; no vertex attributes (vertex ids 0,1,2 -> (-1,-1),(3,-1),(-1,3)).
void main() {
    vec2 p = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);
    gl_Position = vec4(p, 0.0, 1.0);
}
)";

// The fragment shader after its #version line; fragment_source() puts the variant's #define between.
constexpr const char* kFragmentShader = R"(
precision highp float;
precision highp int;
precision highp sampler2D;

uniform sampler2D u_content;  // GL_RGBA16F, linear light (decoded from sRGB once per frame on upload), GL_LINEAR
uniform sampler2D u_warp;     // GL_RGBA32F (u, v, blend weight when the blend mask has the warp's size);
                              // u < kNoContent marks "no content"
uniform sampler2D u_blend;    // GL_R32F weight in linear light (the general variant's bilinear blend)
uniform sampler2D u_lut;      // GL_RG32F, (N - 1) x 3: row ch, texel i = (lut[ch][i], lut[ch][i + 1])
uniform sampler2D u_beta;     // GL_RGBA32F black offset per channel, linear light (read only with HAS_BETA)
uniform sampler2D u_indirect; // GL_RGBA32F screen's own light in content space, content units (only HAS_INDIRECT)
uniform vec2 u_output_size;   // projector pixels
uniform vec2 u_warp_scale;    // warp size / output size (exactly 1.0 when equal)
uniform vec2 u_blend_scale;   // blend size / output size
uniform vec2 u_beta_scale;    // beta size / output size
uniform vec2 u_content_scale;   // late warp: content uv' = uv * scale + offset
uniform vec2 u_content_offset;

out vec4 o_color;

const float kNoContent = -1.0e29;

// The 2x2 texels around q (texel-centre coordinates: texel i is centred at q = i), indices clamped
// to the map's edge, and the fractional position between them.
struct Taps { ivec2 lo; ivec2 hi; vec2 f; };

Taps taps_at(vec2 q, ivec2 size) {
    vec2 base = floor(q);
    Taps t;
    t.f = q - base;
    ivec2 b = ivec2(base);
    t.lo = clamp(b, ivec2(0), size - ivec2(1));
    t.hi = clamp(b + ivec2(1), ivec2(0), size - ivec2(1));
    return t;
}

vec4 weights(vec2 f) {
    return vec4((1.0 - f.x) * (1.0 - f.y), f.x * (1.0 - f.y), (1.0 - f.x) * f.y, f.x * f.y);
}

#ifdef EXACT_MAPS
// Every map has the target's size: p * scale - 0.5 is the integer texel index itself, so the
// bilinear weights are (1, 0, 0, 0) and one fetch gives bit for bit what four would.
ivec2 texel_of(vec2 p) { return ivec2(floor(p)); }

// The warp texel carries the blend weight too (the maps have the same size): one fetch for both.
bool warp_blend_at(vec2 p, out vec2 uv, out float weight) {
    vec3 t = texelFetch(u_warp, texel_of(p), 0).rgb;
    uv = t.rg;
    weight = t.b;
    return uv.x >= kNoContent;
}

#ifdef HAS_BETA
vec3 beta_at(vec2 p) { return texelFetch(u_beta, texel_of(p), 0).rgb; }
#endif
#else
// False when a texel with non-zero weight has no content.
bool warp_at(vec2 p, out vec2 uv) {
    Taps t = taps_at(p * u_warp_scale - 0.5, textureSize(u_warp, 0));
    vec2 a = texelFetch(u_warp, t.lo, 0).rg;
    vec2 b = texelFetch(u_warp, ivec2(t.hi.x, t.lo.y), 0).rg;
    vec2 c = texelFetch(u_warp, ivec2(t.lo.x, t.hi.y), 0).rg;
    vec2 d = texelFetch(u_warp, t.hi, 0).rg;
    vec4 w = weights(t.f);
    bvec4 none = lessThan(vec4(a.x, b.x, c.x, d.x), vec4(kNoContent));
    if ((none.x && w.x > 0.0) || (none.y && w.y > 0.0) || (none.z && w.z > 0.0) || (none.w && w.w > 0.0)) {
        return false;
    }
    // Zero the markers of zero-weight texels so they cannot leak into the sum.
    a = none.x ? vec2(0.0) : a;
    b = none.y ? vec2(0.0) : b;
    c = none.z ? vec2(0.0) : c;
    d = none.w ? vec2(0.0) : d;
    uv = a * w.x + b * w.y + c * w.z + d * w.w;
    return true;
}

float blend_at(vec2 p) {
    Taps t = taps_at(p * u_blend_scale - 0.5, textureSize(u_blend, 0));
    vec4 w = weights(t.f);
    return texelFetch(u_blend, t.lo, 0).r * w.x + texelFetch(u_blend, ivec2(t.hi.x, t.lo.y), 0).r * w.y +
           texelFetch(u_blend, ivec2(t.lo.x, t.hi.y), 0).r * w.z + texelFetch(u_blend, t.hi, 0).r * w.w;
}

bool warp_blend_at(vec2 p, out vec2 uv, out float weight) {
    if (!warp_at(p, uv)) return false;
    weight = blend_at(p);
    return true;
}

// Same grid convention as the blend (sample_beta in appliance/warp/warp_sampling.h), per channel.
#ifdef HAS_BETA
vec3 beta_at(vec2 p) {
    Taps t = taps_at(p * u_beta_scale - 0.5, textureSize(u_beta, 0));
    vec4 w = weights(t.f);
    return texelFetch(u_beta, t.lo, 0).rgb * w.x + texelFetch(u_beta, ivec2(t.hi.x, t.lo.y), 0).rgb * w.y +
           texelFetch(u_beta, ivec2(t.lo.x, t.hi.y), 0).rgb * w.z + texelFetch(u_beta, t.hi, 0).rgb * w.w;
}
#endif
#endif

#ifdef HAS_INDIRECT
// The screen's own light at content point uv (the warp's, before the late warp's transform: the
// field lies on the screen). Bilinear with the content's pixel-centre convention and edge clamping,
// sample_content's (appliance/warp/composite.h). uv is clamped first because the no-content
// marker would overflow the float-to-int conversion; valid uv are uploaded within [-1, 2], where
// the clamp changes nothing.
vec3 indirect_at(vec2 uv) {
    ivec2 size = textureSize(u_indirect, 0);
    Taps t = taps_at(clamp(uv, -1.0, 2.0) * vec2(size) - 0.5, size);
    vec4 w = weights(t.f);
    return texelFetch(u_indirect, t.lo, 0).rgb * w.x + texelFetch(u_indirect, ivec2(t.hi.x, t.lo.y), 0).rgb * w.y +
           texelFetch(u_indirect, ivec2(t.lo.x, t.hi.y), 0).rgb * w.z + texelFetch(u_indirect, t.hi, 0).rgb * w.w;
}
#endif

// Bilinear in linear light by the texture unit (GL_LINEAR on a half-float texture, filterable in
// core GLES 3.0): the same taps and weights as taps_at with edge clamping, the texels already
// decoded to linear light on upload. One filtered fetch instead of four fetches and the weighting.
vec3 content_at(vec2 uv) { return texture(u_content, uv).rgb; }

// Each texel holds an entry and its successor, so one fetch per channel gives both ends of the
// linear piece (three fetches instead of six; the same values, the same arithmetic).
vec3 apply_lut(vec3 x) {
    int n = textureSize(u_lut, 0).x + 1;
    vec3 pos = clamp(x, 0.0, 1.0) * float(n - 1);
    ivec3 i = min(ivec3(floor(pos)), ivec3(n - 2));
    vec3 f = pos - vec3(i);
    vec2 r = texelFetch(u_lut, ivec2(i.r, 0), 0).rg;
    vec2 g = texelFetch(u_lut, ivec2(i.g, 1), 0).rg;
    vec2 b = texelFetch(u_lut, ivec2(i.b, 2), 0).rg;
    return vec3(r.x, g.x, b.x) * (1.0 - f) + vec3(r.y, g.y, b.y) * f;
}

void main() {
    // Output pixel centre with y down from the top row (GL window y grows up).
    vec2 p = vec2(gl_FragCoord.x, u_output_size.y - gl_FragCoord.y);
    vec2 uv;
    float weight;
    // A select rather than an early return: a software rasteriser runs both sides of a divergent
    // branch anyway, and the no-content marker's uv is clamped to the content's edge by the fetch.
    bool content = warp_blend_at(p, uv, weight);
    vec3 content_light = content_at(uv * u_content_scale + u_content_offset);
#ifdef HAS_INDIRECT
    // The screen's own light is already on the screen: take it off the content, before the blend
    // (Bimber et al., IEEE VR 2006); light cannot be negative.
    content_light = max(content_light - indirect_at(uv), 0.0);
#endif
    vec3 linear = content_light * weight;
#ifdef HAS_BETA
    linear += beta_at(p);  // added after the blend, not scaled by the content (docs/calibration.md)
#endif
    o_color = content ? vec4(apply_lut(linear), 1.0) : vec4(0.0, 0.0, 0.0, 1.0);
}
)";

std::string size_text(ImageSize s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

bool fits(ImageSize s, GLint max_size) {
    return s.width > 0 && s.height > 0 && s.width <= max_size && s.height <= max_size;
}

Status check_size(std::string_view what, ImageSize s, GLint max_size) {
    if (s.width <= 0 || s.height <= 0) {
        return make_error(EINVAL, std::string(what) + " size " + size_text(s) + " is empty");
    }
    if (!fits(s, max_size)) {
        return make_error(E2BIG, std::string(what) + " size " + size_text(s) + " exceeds GL_MAX_TEXTURE_SIZE " +
                                     std::to_string(max_size));
    }
    return {};
}

// A 2D texture with one level and edge clamping. Nearest filtering for the 32-bit float maps
// (filtered in the shader: GLES 3.0 does not filter 32-bit float formats); GL_LINEAR only for
// half-float textures, which core GLES 3.0 filters.
Result<GlTexture> upload(std::string_view what, GLenum internal_format, ImageSize size, GLenum format, GLenum type,
                         const void* data, GLint filter = GL_NEAREST) {
    GlTexture texture = make_texture();
    glBindTexture(GL_TEXTURE_2D, texture.get());
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, static_cast<GLint>(internal_format), size.width, size.height, 0, format, type, data);
    if (auto s = gl_check("upload " + std::string(what)); !s) return s.error();
    return texture;
}

// RGB float texels padded to RGBA (alpha 0, never read): a software rasteriser (llvmpipe) stores
// three-channel formats as four channels, so an RGB upload is converted texel by texel and an RGB
// fetch is slower than an RGBA one. Writes into `rgba`, so a per-frame caller can keep its storage.
void pad_to_rgba(const std::vector<float>& rgb, std::vector<float>& rgba) {
    rgba.assign(rgb.size() / 3 * 4, 0.0f);
    for (std::size_t i = 0, k = 0; i + 2 < rgb.size(); i += 3, k += 4) std::copy_n(&rgb[i], 3, &rgba[k]);
}

// The black offset (beta) map: RGBA32F, or an empty texture when the calibration has none (0 x 0
// and no values; the draw then binds the renderer's placeholder and skips the lookups).
Result<GlTexture> upload_beta(const std::string& who, const BlackOffset& beta, GLint max_size) {
    if (beta.size.width == 0 && beta.size.height == 0 && beta.rgb.empty()) return GlTexture{};
    if (auto s = check_size(who + " beta map", beta.size, max_size); !s) return s.error();
    if (beta.rgb.size() != static_cast<std::size_t>(beta.size.pixel_count()) * 3) {
        return make_error(EINVAL, who + ": beta map " + size_text(beta.size) + " holds " +
                                      std::to_string(beta.rgb.size()) + " values, expected width*height*3");
    }
    const auto bad = std::find_if(beta.rgb.begin(), beta.rgb.end(), [](float b) { return !std::isfinite(b); });
    if (bad != beta.rgb.end()) {
        const auto i = static_cast<std::size_t>(bad - beta.rgb.begin());
        const auto texel = static_cast<int>(i / 3);
        return make_error(EINVAL, who + ": beta map has a non-finite offset at (" +
                                      std::to_string(texel % beta.size.width) + ", " +
                                      std::to_string(texel / beta.size.width) + ") channel " + std::to_string(i % 3));
    }
    std::vector<float> rgba;
    pad_to_rgba(beta.rgb, rgba);
    return upload(who + " beta map", GL_RGBA32F, beta.size, GL_RGBA, GL_FLOAT, rgba.data());
}

// set_indirect_light's checks, before anything is uploaded (so a bad field leaves the old one).
Status check_indirect_light(const RgbFloatImage& field, GLint max_size) {
    if (auto s = check_size("indirect light field", field.size, max_size); !s) return s;
    if (field.pixels.size() != static_cast<std::size_t>(field.size.pixel_count()) * 3) {
        return make_error(EINVAL, "indirect light field " + size_text(field.size) + " holds " +
                                      std::to_string(field.pixels.size()) + " values, expected width*height*3");
    }
    // Negative light would brighten the content instead of taking the screen's own light off it.
    const auto bad =
        std::find_if(field.pixels.begin(), field.pixels.end(), [](float v) { return !std::isfinite(v) || v < 0.0f; });
    if (bad == field.pixels.end()) return {};
    const auto i = static_cast<std::size_t>(bad - field.pixels.begin());
    const auto texel = static_cast<int>(i / 3);
    return make_error(EINVAL, "indirect light field has value " + std::to_string(*bad) + " at (" +
                                  std::to_string(texel % field.size.width) + ", " +
                                  std::to_string(texel / field.size.width) + ") channel " + std::to_string(i % 3) +
                                  ", must be finite and >= 0");
}

// IEEE 754 binary32 -> binary16, round to nearest even; finite inputs within the half range
// (the sRGB decode table: 0 and normal numbers in [3e-4, 1]).
std::uint16_t to_half(float value) {
    std::uint32_t x = 0;
    std::memcpy(&x, &value, sizeof x);
    const std::uint32_t sign = (x >> 16) & 0x8000u;
    const int exponent = static_cast<int>((x >> 23) & 0xffu) - 127 + 15;
    std::uint32_t mantissa = x & 0x7fffffu;
    if (exponent >= 31) return static_cast<std::uint16_t>(sign | 0x7c00u);  // beyond the range: infinity
    int shift = 13;
    std::uint32_t bits = (static_cast<std::uint32_t>(std::max(exponent, 0)) << 10);
    if (exponent <= 0) {  // subnormal half (or zero): the implicit 1 becomes explicit
        if (exponent < -10) return static_cast<std::uint16_t>(sign);
        mantissa |= 0x800000u;
        shift = 14 - exponent;
        bits = 0;
    }
    bits |= mantissa >> shift;
    const std::uint32_t rest = mantissa & ((1u << shift) - 1u);
    const std::uint32_t halfway = 1u << (shift - 1);
    if (rest > halfway || (rest == halfway && (bits & 1u) != 0)) ++bits;  // a carry moves into the exponent
    return static_cast<std::uint16_t>(sign | bits);
}

// srgb8_decode_table() as half floats: what the content texture holds for each 8-bit code.
const std::array<std::uint16_t, 256>& srgb8_decode_half_table() {
    static const std::array<std::uint16_t, 256> table = [] {
        std::array<std::uint16_t, 256> t{};
        const std::array<float, 256>& decode = srgb8_decode_table();
        std::transform(decode.begin(), decode.end(), t.begin(), to_half);
        return t;
    }();
    return table;
}

}  // namespace

Result<WarpBlendRenderer::Program> WarpBlendRenderer::make_program(bool exact_maps, bool has_beta, bool has_indirect) {
    const std::string fragment = std::string("#version 300 es\n") + (exact_maps ? "#define EXACT_MAPS 1\n" : "") +
                                 (has_beta ? "#define HAS_BETA 1\n" : "") +
                                 (has_indirect ? "#define HAS_INDIRECT 1\n" : "") + kFragmentShader;
    auto linked = link_program(kVertexShader, fragment);
    if (!linked) {
        return with_context(linked.error(), std::string("WarpBlendRenderer (") + (exact_maps ? "exact" : "general") +
                                                " maps, " + (has_beta ? "with" : "without") + " beta, " +
                                                (has_indirect ? "with" : "without") + " indirect light)");
    }
    Program p;
    p.program = std::move(linked.value());
    const GLuint id = p.program.get();
    glUseProgram(id);
    glUniform1i(glGetUniformLocation(id, "u_content"), 0);
    glUniform1i(glGetUniformLocation(id, "u_warp"), 1);
    glUniform1i(glGetUniformLocation(id, "u_blend"), 2);
    glUniform1i(glGetUniformLocation(id, "u_lut"), 3);
    glUniform1i(glGetUniformLocation(id, "u_beta"), 4);
    glUniform1i(glGetUniformLocation(id, "u_indirect"), 5);  // location -1 (ignored) in variants without it
    p.output_size = glGetUniformLocation(id, "u_output_size");
    p.warp_scale = glGetUniformLocation(id, "u_warp_scale");
    p.blend_scale = glGetUniformLocation(id, "u_blend_scale");
    p.beta_scale = glGetUniformLocation(id, "u_beta_scale");
    p.content_scale = glGetUniformLocation(id, "u_content_scale");
    p.content_offset = glGetUniformLocation(id, "u_content_offset");
    return p;
}

Status WarpBlendRenderer::link_programs(bool has_indirect) {
    for (const bool exact : {false, true}) {
        for (const bool beta : {false, true}) {
            auto program = make_program(exact, beta, has_indirect);
            if (!program) return program.error();
            programs_[program_index(exact, beta, has_indirect)] = std::move(program.value());
        }
    }
    return {};
}

Result<WarpBlendRenderer> WarpBlendRenderer::create() {
    // Without a current context every GL call is silently ignored; say so instead.
    if (eglGetCurrentContext() == EGL_NO_CONTEXT) {
        return make_error(EINVAL, "WarpBlendRenderer::create: no EGL context is current on this thread");
    }
    WarpBlendRenderer r;
    if (auto s = r.link_programs(false); !s) return s.error();
    GLint max_texture = 0;
    GLint max_renderbuffer = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_texture);
    glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_renderbuffer);
    r.max_texture_size_ = std::min(max_texture, max_renderbuffer);
    // Bound on the beta unit for projectors without a beta map and on the indirect light's unit
    // without a field, so no unit ever holds an incomplete texture; the shader does not read it
    // then (the variants without HAS_BETA or HAS_INDIRECT).
    const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    auto placeholder = upload("zero placeholder", GL_RGBA32F, ImageSize{1, 1}, GL_RGBA, GL_FLOAT, zero);
    if (!placeholder) return placeholder.error();
    r.zero_rgb_ = std::move(placeholder.value());
    if (auto s = gl_check("WarpBlendRenderer::create"); !s) return s.error();
    return r;
}

Status WarpBlendRenderer::set_content(const Rgb8Image& frame) {
    if (auto s = check_size("content frame", frame.size, max_texture_size_); !s) return s;
    if (frame.pixels.size() != static_cast<std::size_t>(frame.size.pixel_count()) * 3) {
        return make_error(EINVAL, "content frame " + size_text(frame.size) + " holds " +
                                      std::to_string(frame.pixels.size()) + " values, expected width*height*3");
    }
    // Decoded to linear light here, once per frame, rather than by the texture unit at every fetch
    // of every output pixel of every draw (a software rasteriser's largest cost); half floats, so
    // that the texture unit may filter them (docs/outputs.md: precision); RGBA, alpha 1 and never
    // read, for the reason pad_to_rgba gives.
    const std::array<std::uint16_t, 256>& decode = srgb8_decode_half_table();
    const std::size_t pixel_count = frame.pixels.size() / 3;
    content_linear_.resize(pixel_count * 4);
    for (std::size_t i = 0; i < pixel_count; ++i) {
        content_linear_[4 * i] = decode[frame.pixels[3 * i]];
        content_linear_[4 * i + 1] = decode[frame.pixels[3 * i + 1]];
        content_linear_[4 * i + 2] = decode[frame.pixels[3 * i + 2]];
        content_linear_[4 * i + 3] = kHalfOne;
    }
    if (content_.valid() && frame.size == content_size_) {
        glBindTexture(GL_TEXTURE_2D, content_.get());
        glPixelStorei(GL_UNPACK_ALIGNMENT, 2);
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, frame.size.width, frame.size.height, GL_RGBA, GL_HALF_FLOAT,
                        content_linear_.data());
        return gl_check("upload content frame");
    }
    auto texture =
        upload("content frame", GL_RGBA16F, frame.size, GL_RGBA, GL_HALF_FLOAT, content_linear_.data(), GL_LINEAR);
    if (!texture) return texture.error();
    content_ = std::move(texture.value());
    content_size_ = frame.size;
    return {};
}

Status WarpBlendRenderer::set_indirect_light(const RgbFloatImage& field) {
    if (field.size == ImageSize{} && field.pixels.empty()) {  // none: the draws use the variants without it
        indirect_ = GlTexture{};
        indirect_size_ = {};
        return {};
    }
    if (auto s = check_indirect_light(field, max_texture_size_); !s) return s;
    // The variants with the lookup are linked on the first field, not at create(): most screens
    // have none, and linking is the larger part of create()'s time on a software rasteriser.
    if (!programs_[program_index(false, false, true)].program.valid()) {
        if (auto s = link_programs(true); !s) return s;
    }
    pad_to_rgba(field.pixels, indirect_rgba_);
    if (indirect_.valid() && field.size == indirect_size_) {  // every frame: no reallocation
        glBindTexture(GL_TEXTURE_2D, indirect_.get());
        glPixelStorei(GL_UNPACK_ALIGNMENT, 4);  // float rows are always 4-byte aligned
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, field.size.width, field.size.height, GL_RGBA, GL_FLOAT,
                        indirect_rgba_.data());
        return gl_check("upload indirect light field");
    }
    auto texture = upload("indirect light field", GL_RGBA32F, field.size, GL_RGBA, GL_FLOAT, indirect_rgba_.data());
    if (!texture) return texture.error();
    indirect_ = std::move(texture.value());
    indirect_size_ = field.size;
    return {};
}

Result<std::size_t> WarpBlendRenderer::add_projector(const ProjectorCalibration& c) {
    auto p = make_projector(c);
    if (!p) return p.error();
    projectors_.push_back(std::move(p).value());
    return projectors_.size() - 1;
}

Status WarpBlendRenderer::replace_projector(std::size_t index, const ProjectorCalibration& c) {
    if (index >= projectors_.size()) {
        return make_error(EINVAL, "projector index " + std::to_string(index) + " out of range (have " +
                                      std::to_string(projectors_.size()) + ")");
    }
    auto p = make_projector(c);  // the old textures stay in use until this succeeded
    if (!p) return p.error();
    projectors_[index] = std::move(p).value();
    return {};
}

Result<WarpBlendRenderer::Projector> WarpBlendRenderer::make_projector(const ProjectorCalibration& c) const {
    const std::string who = "projector '" + c.id + "'";
    if (auto s = check_size(who + " output", c.output, max_texture_size_); !s) return s.error();
    if (auto s = check_size(who + " warp map", c.warp.size, max_texture_size_); !s) return s.error();
    if (auto s = check_size(who + " blend mask", c.blend.size, max_texture_size_); !s) return s.error();
    if (c.warp.uv.size() != static_cast<std::size_t>(c.warp.size.pixel_count()) * 2) {
        return make_error(EINVAL, who + ": warp map " + size_text(c.warp.size) + " holds " +
                                      std::to_string(c.warp.uv.size()) + " values, expected width*height*2");
    }
    if (c.blend.weight.size() != static_cast<std::size_t>(c.blend.size.pixel_count())) {
        return make_error(EINVAL, who + ": blend mask " + size_text(c.blend.size) + " holds " +
                                      std::to_string(c.blend.weight.size()) + " values, expected width*height");
    }
    if (!std::all_of(c.blend.weight.begin(), c.blend.weight.end(), [](float w) { return std::isfinite(w); })) {
        return make_error(EINVAL, who + ": blend mask has a non-finite weight");
    }
    const std::size_t n = c.response.lut[0].size();
    if (n < 2 || c.response.lut[1].size() != n || c.response.lut[2].size() != n) {
        return make_error(EINVAL, who + ": response LUT channels must have the same length >= 2 (have " +
                                      std::to_string(c.response.lut[0].size()) + ", " +
                                      std::to_string(c.response.lut[1].size()) + ", " +
                                      std::to_string(c.response.lut[2].size()) + ")");
    }
    if (n > static_cast<std::size_t>(max_texture_size_)) {
        return make_error(E2BIG, who + ": response LUT has " + std::to_string(n) +
                                     " entries, more than GL_MAX_TEXTURE_SIZE " + std::to_string(max_texture_size_));
    }

    // (u, v, blend weight, 0; RGBA: pad_to_rgba): the exact-maps shader reads both maps with one fetch; the weight is
    // only there (and only read) when the blend mask has the warp map's size.
    const bool weight_in_warp = c.blend.size == c.warp.size;
    std::vector<float> uvw(c.warp.uv.size() / 2 * 4);
    for (std::size_t i = 0, k = 0; i < c.warp.uv.size(); i += 2, k += 4) {
        const float u = c.warp.uv[i];
        const float v = c.warp.uv[i + 1];
        const bool valid = std::isfinite(u) && std::isfinite(v);
        uvw[k] = valid ? std::clamp(u, -1.0f, 2.0f) : kNoContentUpload;
        uvw[k + 1] = valid ? std::clamp(v, -1.0f, 2.0f) : kNoContentUpload;
        uvw[k + 2] = weight_in_warp ? c.blend.weight[i / 2] : 0.0f;
    }
    // Row ch, texel i: (lut[ch][i], lut[ch][i + 1]), the two ends of linear piece i (see apply_lut).
    std::vector<float> lut((n - 1) * 3 * 2);
    for (std::size_t ch = 0; ch < 3; ++ch) {
        const auto& entries = c.response.lut[ch];
        if (!std::all_of(entries.begin(), entries.end(), [](float v) { return std::isfinite(v); })) {
            return make_error(EINVAL, who + ": response LUT has a non-finite entry");
        }
        for (std::size_t i = 0; i + 1 < n; ++i) {
            lut[(ch * (n - 1) + i) * 2] = entries[i];
            lut[(ch * (n - 1) + i) * 2 + 1] = entries[i + 1];
        }
    }

    Projector p;
    p.output = c.output;
    p.warp_size = c.warp.size;
    p.blend_size = c.blend.size;
    auto warp = upload(who + " warp map", GL_RGBA32F, c.warp.size, GL_RGBA, GL_FLOAT, uvw.data());
    if (!warp) return warp.error();
    auto blend = upload(who + " blend mask", GL_R32F, c.blend.size, GL_RED, GL_FLOAT, c.blend.weight.data());
    if (!blend) return blend.error();
    auto lut_texture =
        upload(who + " response LUT", GL_RG32F, ImageSize{static_cast<int>(n - 1), 3}, GL_RG, GL_FLOAT, lut.data());
    if (!lut_texture) return lut_texture.error();
    auto beta = upload_beta(who, c.beta, max_texture_size_);
    if (!beta) return beta.error();
    p.beta_size = c.beta.size;
    p.beta = std::move(beta.value());
    p.warp = std::move(warp.value());
    p.blend = std::move(blend.value());
    p.lut = std::move(lut_texture.value());
    return p;
}

Status WarpBlendRenderer::check_index(std::size_t index) const {
    if (index >= projectors_.size()) {
        return make_error(EINVAL, "projector index " + std::to_string(index) + " out of range (have " +
                                      std::to_string(projectors_.size()) + ")");
    }
    if (!content_.valid()) return make_error(EINVAL, "no content frame: call set_content() first");
    return {};
}

Status WarpBlendRenderer::draw(std::size_t index) {
    if (auto s = check_index(index); !s) return s;
    return draw(index, projectors_[index].output);
}

Status WarpBlendRenderer::draw(std::size_t index, ImageSize target) {
    if (auto s = check_index(index); !s) return s;
    if (auto s = check_size("draw target", target, max_texture_size_); !s) return s;
    const Projector& p = projectors_[index];
    const bool has_beta = p.beta.valid();
    const bool exact = p.warp_size == target && p.blend_size == target && (!has_beta || p.beta_size == target);
    const bool has_indirect = indirect_.valid();
    const Program& program = programs_[program_index(exact, has_beta, has_indirect)];
    glUseProgram(program.program.get());
    // The shader maps each target pixel centre to warp/blend coordinates by size ratios, so a
    // target larger or smaller than the calibration's output is the same picture resampled.
    const auto out_w = static_cast<float>(target.width);
    const auto out_h = static_cast<float>(target.height);
    glUniform2f(program.output_size, out_w, out_h);
    glUniform2f(program.warp_scale, static_cast<float>(p.warp_size.width) / out_w,
                static_cast<float>(p.warp_size.height) / out_h);
    glUniform2f(program.blend_scale, static_cast<float>(p.blend_size.width) / out_w,
                static_cast<float>(p.blend_size.height) / out_h);
    glUniform2f(program.beta_scale, has_beta ? static_cast<float>(p.beta_size.width) / out_w : 0.0f,
                has_beta ? static_cast<float>(p.beta_size.height) / out_h : 0.0f);
    glUniform2f(program.content_scale, transform_.scale_u, transform_.scale_v);
    glUniform2f(program.content_offset, transform_.offset_u, transform_.offset_v);
    const GLuint textures[] = {content_.get(),
                               p.warp.get(),
                               p.blend.get(),
                               p.lut.get(),
                               has_beta ? p.beta.get() : zero_rgb_.get(),
                               has_indirect ? indirect_.get() : zero_rgb_.get()};
    for (GLuint unit = 0; unit < 6; ++unit) {
        glActiveTexture(GL_TEXTURE0 + unit);
        glBindTexture(GL_TEXTURE_2D, textures[unit]);
    }
    glActiveTexture(GL_TEXTURE0);
    // Fixed-function state that would alter the pixels; dithering is on by default in GL.
    glDisable(GL_BLEND);
    glDisable(GL_DITHER);
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_STENCIL_TEST);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glViewport(0, 0, target.width, target.height);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    return gl_check("WarpBlendRenderer::draw");
}

Result<Rgb8Image> WarpBlendRenderer::render(std::size_t index) {
    if (auto s = check_index(index); !s) return s.error();
    Projector& p = projectors_[index];
    if (!p.target.fbo.valid()) {
        auto target = make_render_target(p.output);
        if (!target) return with_context(target.error(), "projector " + std::to_string(index));
        p.target = std::move(target.value());
    }
    glBindFramebuffer(GL_FRAMEBUFFER, p.target.fbo.get());
    if (auto s = draw(index); !s) return s.error();
    Rgb8Image out(p.output);
    if (auto s = read_rgb8(p.output, out, readback_); !s) return s.error();
    return out;
}

}  // namespace mogao
