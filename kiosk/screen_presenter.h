// SPDX-License-Identifier: Apache-2.0
// ScreenPresenter: puts one content frame on every projector output of an OutputBackend, through
// each output's projector calibration (warp, blend, response: drivers/egl/warp_blend_renderer.h),
// and tells when a frame has reached the screen.
//
// show(content, tag) uploads the frame once and presents it on every output that is ready;
// outputs still waiting for a page flip are marked and get the newest content as soon as
// on_ready() reports them (after OutputBackend::dispatch_events). An output therefore never shows
// an older frame after a newer one, and never gets a frame queued behind a pending flip.
// A frame is "on screen" when every lit output has presented it or a newer one and, for KMS, its
// flip completed (headless presents complete on return): take_completed() then returns its tag.
// Tags must increase from show() to show() (the kiosk uses 0 for its own screens and the request
// id for farm frames).
//
// Threading: the backend's thread (its GL context). Errors: common/result.h codes from the
// backend/renderer (EINVAL, EIO, ...); a failed output is left dirty and retried on the next
// show/repaint/on_ready.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "common/projector_calibration.h"
#include "drivers/output.h"
#include "common/result.h"
#include "common/image.h"

namespace mogao {

class ScreenPresenter {
public:
    // Uploads every projector of `screen` to the backend's renderer and assigns them to outputs
    // (projector_assignment.h; notes appended). EINVAL when no output gets a projector.
    [[nodiscard]] static Result<ScreenPresenter> create(OutputBackend& backend, const ScreenCalibration& screen,
                                                        std::vector<std::string>* notes);

    // New content (sRGB RGB8, rows top first) with a tag newer than the previous one.
    [[nodiscard]] Status show(const Rgb8Image& content, std::uint64_t tag);

    // Presents the current content again on every ready output that has nothing newer pending
    // (the idle repaint of the display tick). No-op before the first show().
    [[nodiscard]] Status repaint();

    // Outputs that became ready (dispatch_events); presents pending content on them.
    [[nodiscard]] Status on_ready(const std::vector<std::size_t>& outputs);

    // The newest tag now on screen on every lit output, once per tag; nullopt when nothing new.
    [[nodiscard]] std::optional<std::uint64_t> take_completed();

    // Presents performed by the last show/repaint/on_ready call (one per output).
    [[nodiscard]] std::size_t last_presents() const { return last_presents_; }
    [[nodiscard]] std::uint64_t current_tag() const { return tag_; }
    [[nodiscard]] const std::vector<std::optional<std::size_t>>& projector_of() const { return projector_of_; }

    // Called after each output is presented, so that a caller can show progress within one round:
    // the kiosk feeds the service watchdog here, because a round of several outputs on a slow
    // software rasteriser (llvmpipe under QEMU's TCG: 7 s for three outputs) can outlast WatchdogSec
    // while every single output takes a fraction of it.
    void on_output_presented(std::function<void()> callback) { output_presented_ = std::move(callback); }

private:
    struct OutputState {
        bool lit = false;
        std::size_t projector = 0;   // renderer index
        bool dirty = false;          // current content not yet presented here
        bool in_flight = false;      // presented, flip pending
        std::uint64_t flight_tag = 0;
        std::optional<std::uint64_t> shown_tag;  // on screen
    };

    ScreenPresenter(OutputBackend& backend, std::vector<std::optional<std::size_t>> projector_of,
                    std::vector<OutputState> states)
        : backend_(&backend), projector_of_(std::move(projector_of)), states_(std::move(states)) {}
    [[nodiscard]] Status present_dirty();

    OutputBackend* backend_;
    std::vector<std::optional<std::size_t>> projector_of_;
    std::vector<OutputState> states_;
    bool has_content_ = false;
    std::uint64_t tag_ = 0;
    std::optional<std::uint64_t> completed_;
    std::size_t last_presents_ = 0;
    std::function<void()> output_presented_;
};

}  // namespace mogao
