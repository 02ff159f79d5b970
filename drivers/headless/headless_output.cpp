// SPDX-License-Identifier: Apache-2.0
#include "drivers/headless/headless_output.h"

#include <time.h>

#include <cstdio>
#include <exception>
#include <string>
#include <utility>

#include "common/png_io.h"

namespace mogao {

namespace {

std::int64_t now_realtime_ns() {
    timespec ts{};
    clock_gettime(CLOCK_REALTIME, &ts);
    return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

}  // namespace

Result<std::unique_ptr<HeadlessOutputBackend>> HeadlessOutputBackend::create(HeadlessOptions options) {
    if (options.outputs.empty()) return make_error(EINVAL, "headless backend: no outputs requested");
    auto display = EglDisplay::open_surfaceless();
    if (!display) return with_context(display.error(), "headless backend");
    auto context = EglContext::create(display.value(), EGL_NO_CONFIG_KHR);
    if (!context) return with_context(context.error(), "headless backend");
    if (auto s = context->make_current(); !s) return with_context(s.error(), "headless backend");
    auto renderer = WarpBlendRenderer::create();
    if (!renderer) return with_context(renderer.error(), "headless backend");

    std::unique_ptr<HeadlessOutputBackend> backend(
        new HeadlessOutputBackend(std::move(display.value()), std::move(context.value()), std::move(renderer.value())));
    GLint max_size = 0;
    glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_size);
    for (std::size_t i = 0; i < options.outputs.size(); ++i) {
        const ImageSize size = options.outputs[i];
        const std::string name = "headless-" + std::to_string(i);
        if (size.width <= 0 || size.height <= 0 || size.width > max_size || size.height > max_size) {
            return make_error(EINVAL, name + ": size " + std::to_string(size.width) + "x" +
                                          std::to_string(size.height) + " is outside 1.." + std::to_string(max_size));
        }
        auto target = make_render_target(size);
        if (!target) return with_context(target.error(), name);
        backend->targets_.push_back(Target{std::move(target.value()), Rgb8Image{}, 0, false, false, std::nullopt});
        backend->infos_.push_back(OutputInfo{name, size, 0.0});
    }
    backend->png_dir_ = std::move(options.png_dir);
    return backend;
}

HeadlessOutputBackend::HeadlessOutputBackend(EglDisplay display, EglContext context, WarpBlendRenderer renderer)
    : display_(std::move(display)), context_(std::move(context)), renderer_(std::move(renderer)) {}

HeadlessOutputBackend::~HeadlessOutputBackend() {
    // GL names are deleted by the members' destructors; they need this context current.
    (void)context_.make_current();
}

Status HeadlessOutputBackend::check_index(std::size_t i) const {
    if (i >= targets_.size()) {
        return make_error(
            EINVAL, "output " + std::to_string(i) + " out of range (have " + std::to_string(targets_.size()) + ")");
    }
    return {};
}

Status HeadlessOutputBackend::begin_frame(std::size_t i) {
    if (auto s = check_index(i); !s) return s;
    if (auto s = context_.make_current(); !s) return s;
    Target& t = targets_[i];
    glBindFramebuffer(GL_FRAMEBUFFER, t.gl.fbo.get());
    glViewport(0, 0, t.gl.size.width, t.gl.size.height);
    glDisable(GL_SCISSOR_TEST);
    glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    t.begun = true;
    return gl_check("headless begin_frame");
}

Status HeadlessOutputBackend::present(std::size_t i) {
    if (auto s = check_index(i); !s) return s;
    Target& t = targets_[i];
    if (!t.begun) return make_error(EINVAL, infos_[i].name + ": present() without begin_frame()");
    t.begun = false;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, t.gl.fbo.get());
    if (auto s = read_rgb8(t.gl.size, t.last, scratch_); !s) return with_context(s.error(), infos_[i].name);
    t.presented_ns = now_realtime_ns();
    const std::uint64_t frame = t.frames++;
    if (png_dir_.empty()) return {};
    char number[32];
    std::snprintf(number, sizeof number, "-%06llu.png", static_cast<unsigned long long>(frame));
    const auto path = png_dir_ / (infos_[i].name + number);
    try {
        write_png(path, t.last);  // encode/ throws; drivers/ returns errors
    } catch (const std::exception& e) {
        return make_error(EIO, e.what());
    }
    return {};
}

}  // namespace mogao

namespace mogao {

Status HeadlessOutputBackend::stage(std::size_t i) {
    if (auto s = check_index(i); !s) return s;
    const std::uint64_t before = targets_[i].frames;
    Status s = present(i);
    // Staged once read back, even when only its PNG failed (the frame is kept, as present()).
    if (targets_[i].frames != before) targets_[i].staged = true;
    return s;
}

Status HeadlessOutputBackend::commit_round() {
    const std::int64_t now = now_realtime_ns();
    for (Target& t : targets_) {
        if (std::exchange(t.staged, false)) t.presented_ns = now;
    }
    return {};
}

std::optional<std::int64_t> HeadlessOutputBackend::presented_ns(std::size_t i) const {
    return i < targets_.size() ? targets_[i].presented_ns : std::nullopt;
}

}  // namespace mogao
