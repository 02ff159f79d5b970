// SPDX-License-Identifier: Apache-2.0
// Prints milliseconds per projector output for this machine's GL (llvmpipe without a GPU):
// content upload, draw (glFinish'ed) and draw + readback, for one output of --output WxH; then
// the draw of the same output with a per-pixel black offset (beta) map, and its ratio to the draw
// without, measured interleaved in the same run. The draw is also given in CPU milliseconds of the
// whole process (llvmpipe's rasteriser threads included): on a machine shared with other work the
// wall time grows with the load, the CPU time much less, so two builds compare by it.
// The first projector's blend mask is 1x1, so its draws run the general shader variant (bilinear
// warp and blend, four fetches each); a third projector with maps of the output's size runs the
// exact variant that a calibration made for its output (the kiosk's ideal one, an MPCDI at the
// projector's resolution) gets, timed interleaved too, with its ratio to the general draw.
// Usage: mogao_warp_blend_bench [width height [content_width content_height [frames]]]
#include <GLES3/gl3.h>

#include <time.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "drivers/egl/egl_display.h"
#include "drivers/egl/test_pattern.h"
#include "drivers/egl/warp_blend_renderer.h"

namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

double process_cpu_ms() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

int arg(int argc, char** argv, int i, int fallback) { return argc > i ? std::atoi(argv[i]) : fallback; }

}  // namespace

int main(int argc, char** argv) {
    using namespace mogao;
    const ImageSize output{arg(argc, argv, 1, 1024), arg(argc, argv, 2, 768)};
    const ImageSize content_size{arg(argc, argv, 3, 2048), arg(argc, argv, 4, 1024)};
    const int frames = arg(argc, argv, 5, 20);
    if (output.width <= 0 || output.height <= 0 || content_size.width <= 0 || content_size.height <= 0 || frames <= 0) {
        std::fprintf(stderr, "usage: %s [width height [content_width content_height [frames]]]\n", argv[0]);
        return 2;
    }
    auto display = EglDisplay::open_surfaceless();
    if (!display) return std::fprintf(stderr, "%s\n", display.error().message.c_str()), 77;
    auto context = EglContext::create(display.value(), EGL_NO_CONFIG_KHR);
    if (!context || !context->make_current()) return std::fprintf(stderr, "no GLES 3 context\n"), 1;
    {
        auto renderer = WarpBlendRenderer::create();
        if (!renderer) return std::fprintf(stderr, "%s\n", renderer.error().message.c_str()), 1;
        const Rgb8Image content = make_test_pattern(content_size);
        auto index = renderer->add_projector(identity_calibration("bench", output));
        if (!index) return std::fprintf(stderr, "%s\n", index.error().message.c_str()), 1;
        ProjectorCalibration lifted = identity_calibration("bench-beta", output);
        lifted.beta.size = output;
        lifted.beta.rgb.assign(static_cast<std::size_t>(output.pixel_count()) * 3, 0.01f);
        auto beta_index = renderer->add_projector(lifted);
        if (!beta_index) return std::fprintf(stderr, "%s\n", beta_index.error().message.c_str()), 1;
        ProjectorCalibration exact = identity_calibration("bench-exact", output);
        exact.blend.size = output;
        exact.blend.weight.assign(static_cast<std::size_t>(output.pixel_count()), 1.0f);
        auto exact_index = renderer->add_projector(exact);
        if (!exact_index) return std::fprintf(stderr, "%s\n", exact_index.error().message.c_str()), 1;
        if (!renderer->set_content(content) || !renderer->render(*index) || !renderer->render(*beta_index) ||
            !renderer->render(*exact_index)) {
            return 1;  // warm-up (shader JIT, all three FBOs)
        }

        double upload = 0, draw = 0, draw_cpu = 0, readback = 0, draw_beta = 0, draw_exact = 0, draw_exact_cpu = 0;
        for (int f = 0; f < frames; ++f) {
            auto t0 = std::chrono::steady_clock::now();
            if (!renderer->set_content(content)) return 1;
            glFinish();
            upload += ms_since(t0);
            t0 = std::chrono::steady_clock::now();
            const double cpu0 = process_cpu_ms();
            if (!renderer->draw(*index)) return 1;  // into render()'s FBO, still bound
            glFinish();
            draw += ms_since(t0);
            draw_cpu += process_cpu_ms() - cpu0;
            t0 = std::chrono::steady_clock::now();
            if (!renderer->render(*index)) return 1;
            readback += ms_since(t0);
            if (!renderer->render(*beta_index)) return 1;  // binds its FBO; then time the draw alone
            t0 = std::chrono::steady_clock::now();
            if (!renderer->draw(*beta_index)) return 1;
            glFinish();
            draw_beta += ms_since(t0);
            if (!renderer->render(*exact_index)) return 1;  // binds its FBO; then time the draw alone
            t0 = std::chrono::steady_clock::now();
            const double exact_cpu0 = process_cpu_ms();
            if (!renderer->draw(*exact_index)) return 1;
            glFinish();
            draw_exact += ms_since(t0);
            draw_exact_cpu += process_cpu_ms() - exact_cpu0;
        }
        std::printf("renderer: %s\n", reinterpret_cast<const char*>(glGetString(GL_RENDERER)));
        std::printf("output %dx%d, content %dx%d, %d frames (mean ms)\n", output.width, output.height,
                    content_size.width, content_size.height, frames);
        std::printf(
            "  upload content  %8.2f\n  draw            %8.2f  (CPU ms, all threads: %.2f)\n"
            "  draw + readback %8.2f\n",
            upload / frames, draw / frames, draw_cpu / frames, readback / frames);
        std::printf("  draw with beta  %8.2f  (x%.2f of the draw without)\n", draw_beta / frames, draw_beta / draw);
        std::printf("  draw, exact maps %7.2f  (CPU ms, all threads: %.2f; x%.2f of the general draw's CPU)\n",
                    draw_exact / frames, draw_exact_cpu / frames, draw_exact_cpu / draw_cpu);
    }
    return 0;
}
