// SPDX-License-Identifier: Apache-2.0
// ScreenPresenter: puts one content frame on every projector output of an OutputBackend, through
// each output's projector calibration (warp, blend, response: drivers/projector_renderer.h),
// and tells when a frame has reached the screen.
//
// Rounds: a content frame is presented on all lit outputs together, in one round
// (OutputBackend::stage on each, then one commit_round: on KMS one atomic commit for every CRTC).
// A new round starts only when the previous one has completed on every output (all its flip
// events reported through on_ready()); until then show() only records the newest content, and the
// next round presents it. So outputs never show different content frames (no shear at the seams
// while the view turns), an output never shows an older frame after a newer one, and no frame is
// queued behind a pending flip. A frame is "on screen" when its round completed on every lit
// output (headless rounds complete on return): take_completed() then returns its tag.
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

#include "common/image.h"
#include "common/projector_calibration.h"
#include "common/result.h"
#include "drivers/output.h"

namespace mogao {

class ScreenPresenter {
public:
    // Uploads every projector of `screen` to the backend's renderer and assigns them to outputs
    // (projector_assignment.h; notes appended). EINVAL when no output gets a projector.
    [[nodiscard]] static Result<ScreenPresenter> create(OutputBackend& backend, const ScreenCalibration& screen,
                                                        std::vector<std::string>* notes);

    // New content (sRGB RGB8, rows top first) with a tag newer than the previous one.
    [[nodiscard]] Status show(const Rgb8Image& content, std::uint64_t tag);

    // A run-time calibration swap (kiosk/live_calibration/calibration_inbox.h): every projector on an output gets the
    // calibration of the projector with the same id in `screen` (warp, blend, response uploaded
    // again), and the current content is presented again through it as the next round (at once
    // when no round is in flight). The assignment of projectors to outputs is kept. EINVAL, with
    // nothing changed, when a projector on an output has no counterpart in `screen` (a new layout
    // needs a restart); an upload error leaves that projector's old calibration in use.
    [[nodiscard]] Status swap_calibration(const ScreenCalibration& screen);

    // Presents the current content again, as a round on every lit output, when no round is in
    // flight. No-op before the first show().
    [[nodiscard]] Status repaint();

    // The current content is due again (the renderer's content transform changed): the next round
    // draws it, now when no round is in flight and the caller asks (present_due()), or when the
    // round in flight completes. No-op before the first show().
    void invalidate() { dirty_ = dirty_ || has_content_; }
    // Presents the current content as a round when it is due (a show, swap or invalidate() not yet
    // drawn) and no round is in flight: the idle repaint of the display tick, which leaves an
    // unchanged wall alone.
    [[nodiscard]] Status present_due();

    // Outputs that became ready (dispatch_events); once the round in flight completed on all of
    // them, presents pending content as the next round.
    [[nodiscard]] Status on_ready(const std::vector<std::size_t>& outputs);

    // The newest tag now on screen on every lit output, once per tag; nullopt when nothing new.
    [[nodiscard]] std::optional<std::uint64_t> take_completed();

    // Presents performed by the last show/repaint/on_ready call (one per output of its round).
    [[nodiscard]] std::size_t last_presents() const { return last_presents_; }
    [[nodiscard]] std::uint64_t current_tag() const { return tag_; }
    [[nodiscard]] const std::vector<std::optional<std::size_t>>& projector_of() const { return projector_of_; }

    // Called after each output of a round is drawn and staged, so that a caller can show progress within one round:
    // the kiosk feeds the service watchdog here, because a round of several outputs on a slow
    // software rasteriser (llvmpipe under QEMU's TCG: 7 s for three outputs) can outlast WatchdogSec
    // while every single output takes a fraction of it.
    void on_output_presented(std::function<void()> callback) { output_presented_ = std::move(callback); }

private:
    struct OutputState {
        bool lit = false;
        std::size_t projector = 0;               // renderer index
        bool in_flight = false;                  // in the round in flight, its flip pending
        std::optional<std::uint64_t> shown_tag;  // on screen
    };

    ScreenPresenter(OutputBackend& backend, std::vector<std::optional<std::size_t>> projector_of,
                    std::vector<OutputState> states, std::vector<std::string> ids)
        : backend_(&backend),
          projector_of_(std::move(projector_of)),
          states_(std::move(states)),
          renderer_ids_(std::move(ids)) {}
    [[nodiscard]] Status present_round();  // when dirty_ and no round in flight
    [[nodiscard]] bool round_in_flight() const;

    OutputBackend* backend_;
    std::vector<std::optional<std::size_t>> projector_of_;
    std::vector<OutputState> states_;
    std::vector<std::string> renderer_ids_;  // per renderer index: the projector id it draws
    bool has_content_ = false;
    bool dirty_ = false;  // the current content has not started a round yet
    std::uint64_t tag_ = 0;
    std::uint64_t flight_tag_ = 0;  // content of the round in flight
    std::optional<std::uint64_t> completed_;
    std::size_t last_presents_ = 0;
    std::function<void()> output_presented_;
};

}  // namespace mogao
