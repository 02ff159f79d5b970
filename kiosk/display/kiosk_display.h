// SPDX-License-Identifier: Apache-2.0
// KioskDisplay: the kiosk's projector outputs and what it knows about them: the OutputBackend (KMS or
// headless), the ScreenPresenter that warps and blends content onto every output, the headless PNG
// recorder, and the frame accounting -- which farm frames are on screen everywhere (KioskStats:
// motion-to-photon ends there), display rounds, PNGs per round.
//
// After every show / repaint / flip: a round that presented anything is counted (and recorded as
// PNGs), and every frame that is now on screen on all outputs is passed to KioskStats, stamped
// with the time its round reached the screen (KMS: the kernel's page-flip timestamp). Frames shown
// but not yet on screen everywhere (KMS flips pending) wait in a map by request id; a frame overtaken
// on some output by a newer one is dropped from it when the newer one completes.
//
// Errors: presenting and PNG writing are logged as warnings (the show goes on, docs/kiosk.md); the
// backend's event dispatch error is returned (the loop stops on it). Loop thread only (GL context).
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "appliance/decode/last_good_frame.h"
#include "common/projector_calibration.h"
#include "common/result.h"
#include "drivers/output.h"
#include "kiosk/display/frame_indirect_light.h"
#include "kiosk/display/headless_recorder.h"
#include "kiosk/display/screen_presenter.h"
#include "kiosk/stats/kiosk_stats.h"

namespace mogao {

class KioskDisplay {
public:
    // `backend`'s outputs showing `screen` (ScreenPresenter::create; its notes are appended).
    [[nodiscard]] static Result<KioskDisplay> create(std::unique_ptr<OutputBackend> backend, ScreenCalibration screen,
                                                     std::vector<std::string>* notes);

    // What gives the screen's own light to take off each frame for a calibration (frame_indirect_light.h;
    // nullopt: nothing to take off): asked now for the current calibration and again after every swap. Without one
    // (the default) the outputs take nothing off.
    using IndirectLightSource = std::function<std::optional<FrameIndirectLight>(const ScreenCalibration&)>;
    void take_off_indirect_light(IndirectLightSource source);
    [[nodiscard]] bool takes_off_indirect_light() const { return indirect_.has_value(); }

    // Headless PNGs of every k-th round and the composite at exit (the recorder reads `backend`).
    void record_to(HeadlessRecorder recorder) { recorder_.emplace(std::move(recorder)); }

    // The card shown until the first farm frame (tag 0: never counted as a farm frame).
    [[nodiscard]] Status show_connecting_screen(ImageSize content, const std::string& endpoint);
    // A card made for the screen itself (no late warp), under tag 0 like the connecting card.
    [[nodiscard]] Status show_card(const Rgb8Image& card);
    // A decoded farm frame, newer than the one before.
    void show(const ContentFrame& frame);
    // A run-time calibration swap (ScreenPresenter::swap_calibration): the current frame is shown
    // again through `screen`, which the composite uses from now on (on success only; errors: see
    // ScreenPresenter::swap_calibration).
    [[nodiscard]] Status swap_calibration(ScreenCalibration screen);
    [[nodiscard]] const ScreenCalibration& calibration() const { return screen_; }
    // The same frame with different pixels (the on-wall status drawn over it, or taken off): shown at
    // once as the current content under the current frame's tag (not counted as a new farm frame).
    void refresh_content(const Rgb8Image& content);
    // The tick's idle repaint: the current frame again on every output when the wall would change
    // (the late warp's content transform changed since its last round; ScreenPresenter::present_due).
    // An unchanged wall is left alone: a software rasteriser spends tens of ms per output on a round
    // that changes nothing, and a KMS output keeps scanning out its last buffer. While recording
    // (record_to, a PNG every k-th round) a wall left unchanged for k idle ticks is drawn and recorded
    // again, so that a held frame (the farm down) is still in the recording.
    void repaint();
    // Page-flip events of the backend (KMS): outputs ready again get pending content.
    [[nodiscard]] Status on_flip();

    // The first output whose last present has not completed (KMS: no page-flip event) for longer
    // than `timeout` at `now`; nullopt when every output is ready or busy for less. A flip that
    // never completes would otherwise freeze that projector while the loop runs on.
    [[nodiscard]] std::optional<std::size_t> overdue_output(std::chrono::steady_clock::time_point now,
                                                            std::chrono::steady_clock::duration timeout);
    [[nodiscard]] const std::string& output_name(std::size_t i) const { return backend_->outputs().at(i).name; }
    // Every output's last present has completed (KMS: its page flip; headless: always).
    [[nodiscard]] bool all_outputs_ready() const;

    // Writes <png dir>/screen-composite.png when recording (logged; a failure is a warning).
    void write_composite() const;

    [[nodiscard]] std::uint64_t frames_on_screen() const { return frames_on_screen_; }
    [[nodiscard]] KioskStats& stats() { return stats_; }
    [[nodiscard]] const KioskStats& stats() const { return stats_; }
    [[nodiscard]] int event_fd() const { return backend_->event_fd(); }
    [[nodiscard]] const ScreenPresenter& presenter() const { return presenter_; }
    // The late warp's content transform for the rounds from now on (ProjectorRenderer); the
    // connecting screen resets it to the identity. A different transform makes the current frame due
    // again (the next repaint, show or completed round draws it).
    void set_content_transform(const ContentTransform& t);
    [[nodiscard]] ContentTransform content_transform() const { return backend_->renderer().content_transform(); }
    // See ScreenPresenter::on_output_presented (the kiosk feeds its watchdog there).
    void on_output_presented(std::function<void()> callback) { presenter_.on_output_presented(std::move(callback)); }

private:
    KioskDisplay(std::unique_ptr<OutputBackend> backend, ScreenPresenter presenter, ScreenCalibration screen)
        : backend_(std::move(backend)), presenter_(std::move(presenter)), screen_(std::move(screen)) {}
    void account(bool forced = false);  // after every present: rounds, PNGs (forced: recorded), frames now on screen
    void update_indirect_light(const Rgb8Image& content);  // the field for the content about to be shown
    // When the completed round reached the screen (CLOCK_REALTIME ns): the latest
    // OutputBackend::presented_ns of the lit outputs (KMS: page-flip timestamps; headless: the
    // round), or now when the backend cannot tell. Motion-to-photon ends here.
    [[nodiscard]] std::int64_t on_screen_ns() const;

    // Frames on some outputs but not yet on screen everywhere, by request id; bounded, so that an
    // output that never completes cannot grow it.
    static constexpr std::size_t kMaxPendingFrames = 64;

    // Declaration order: released recorder, presenter, then backend (docs/kiosk.md, clean stop).
    std::unique_ptr<OutputBackend> backend_;
    ScreenPresenter presenter_;
    ScreenCalibration screen_;
    std::optional<HeadlessRecorder> recorder_;
    IndirectLightSource indirect_source_;
    std::optional<FrameIndirectLight> indirect_;
    KioskStats stats_;
    std::map<std::uint64_t, PresentedFrame> pending_;
    std::uint64_t frames_on_screen_ = 0;
    std::uint64_t idle_ticks_ = 0;  // repaint() calls since the last round (a recording forces one every k)
    // Per output: since when it has been not ready (a present in flight), as first seen by account().
    std::vector<std::optional<std::chrono::steady_clock::time_point>> busy_since_;
};

}  // namespace mogao
