// SPDX-License-Identifier: Apache-2.0
// HeadlessOutputBackend: projector outputs as offscreen FBOs in a surfaceless EGL context (Mesa;
// llvmpipe on machines without a GPU). For the render farm's previews, CI and the kiosk's
// --headless mode. present() reads each frame back (RGB8, rows top first) and, when png_dir is
// set, writes it as <png_dir>/<name>-<NNNNNN>.png (NNNNNN = that output's frame counter from 0).
// Every present completes synchronously: ready() is always true and event_fd() is -1. Rounds
// (drivers/output.h): stage(i) reads output i back like present(i); commit_round() completes the
// round, stamping presented_ns() of every staged output with the same CLOCK_REALTIME time (the
// presented round's time, what motion-to-photon ends at headless).
//
// Threading: the backend's context is made current on the creating thread; use the backend (and
// destroy it) on that thread.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

#include "drivers/egl/egl_display.h"
#include "drivers/egl/gl_objects.h"
#include "drivers/egl/warp_blend_renderer.h"
#include "drivers/output.h"

namespace mogao {

struct HeadlessOptions {
    std::vector<ImageSize> outputs;  // one entry per output, each at least 1x1
    std::filesystem::path png_dir;   // empty: no files; otherwise an existing, writable folder
};

class HeadlessOutputBackend final : public OutputBackend {
public:
    // ENODEV without a surfaceless EGL display, EINVAL for no outputs or an empty/oversized one.
    [[nodiscard]] static Result<std::unique_ptr<HeadlessOutputBackend>> create(HeadlessOptions options);
    ~HeadlessOutputBackend() override;
    HeadlessOutputBackend(const HeadlessOutputBackend&) = delete;
    HeadlessOutputBackend& operator=(const HeadlessOutputBackend&) = delete;

    [[nodiscard]] const std::vector<OutputInfo>& outputs() const override { return infos_; }
    [[nodiscard]] WarpBlendRenderer& renderer() override { return renderer_; }
    [[nodiscard]] Status begin_frame(std::size_t i) override;
    // EINVAL without begin_frame(i); EIO if the PNG cannot be written (the frame is kept anyway).
    [[nodiscard]] Status present(std::size_t i) override;
    [[nodiscard]] Status stage(std::size_t i) override;
    [[nodiscard]] Status commit_round() override;
    [[nodiscard]] std::optional<std::int64_t> presented_ns(std::size_t i) const override;
    [[nodiscard]] bool ready(std::size_t i) const override { return i < targets_.size(); }
    [[nodiscard]] int event_fd() const override { return -1; }
    [[nodiscard]] Result<std::vector<std::size_t>> dispatch_events() override { return std::vector<std::size_t>{}; }

    // The last presented frame of output `i` (RGB8, rows top first); empty (0x0) before the first.
    [[nodiscard]] const Rgb8Image& last_frame(std::size_t i) const { return targets_.at(i).last; }
    // Frames presented on output `i` so far.
    [[nodiscard]] std::uint64_t frame_count(std::size_t i) const { return targets_.at(i).frames; }

private:
    struct Target {
        GlRenderTarget gl;
        Rgb8Image last;
        std::uint64_t frames = 0;
        bool begun = false;
        bool staged = false;
        std::optional<std::int64_t> presented_ns;
    };

    HeadlessOutputBackend(EglDisplay display, EglContext context, WarpBlendRenderer renderer);
    [[nodiscard]] Status check_index(std::size_t i) const;

    // Declaration order is destruction order reversed: GL objects go before the context, the
    // context before the display.
    EglDisplay display_;
    EglContext context_;
    WarpBlendRenderer renderer_;
    std::vector<Target> targets_;
    std::vector<OutputInfo> infos_;
    std::filesystem::path png_dir_;
    std::vector<std::uint8_t> scratch_;
};

}  // namespace mogao
