// SPDX-License-Identifier: Apache-2.0
// OutputBackend: what the kiosk drives, one instance per GPU/display. Each output is one projector
// (a KMS connector/CRTC pair, or a headless FBO). The frame loop, per new content frame:
//
//   backend.renderer().set_content(frame);                  // upload once (context is current)
//   for each output i with backend.ready(i):
//       backend.begin_frame(i);                             // target bound, cleared to black
//       backend.renderer().draw(projector_of[i]);           // or any GLES drawing
//       backend.present(i);                                 // queue it for display
//   poll(backend.event_fd(), POLLIN) ...; backend.dispatch_events();  // outputs become ready again
//
// Projectors are added with renderer().add_projector(calibration); which projector an output
// shows is the caller's choice (normally the calibration whose output size equals the output's).
// Errors follow common/result.h: EINVAL for a bad output index, EBUSY when an output is not
// ready (its previous frame is still waiting for a flip), EIO/EACCES/... from the kernel or EGL.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/pixel_rect.h"
#include "common/result.h"
#include "drivers/projector_renderer.h"

namespace mogao {

struct OutputInfo {
    std::string name;       // "HDMI-A-1" (KMS connector), "headless-0"
    ImageSize size;         // pixels (the KMS mode's active area)
    double refresh_hz = 0;  // vertical refresh of the mode; 0 for headless
};

class OutputBackend {
public:
    virtual ~OutputBackend() = default;

    [[nodiscard]] virtual const std::vector<OutputInfo>& outputs() const = 0;

    // The renderer that draws this backend's outputs (valid for the backend's lifetime; for GL, it
    // lives in the backend's context, current on the thread that created the backend after
    // create/begin_frame).
    [[nodiscard]] virtual ProjectorRenderer& renderer() = 0;

    // Makes output `i`'s target current and bound to GL_DRAW_FRAMEBUFFER, sets the viewport to the
    // whole output and clears it to black. EBUSY when !ready(i).
    [[nodiscard]] virtual Status begin_frame(std::size_t i) = 0;

    // Queues what was drawn since begin_frame(i) for display. Headless: reads it back (and writes
    // a PNG when configured) and is ready again on return. KMS: swaps, locks the buffer and
    // commits it (first frame: blocking modeset, ready on return; later: non-blocking flip, ready
    // after its flip event was dispatched).
    [[nodiscard]] virtual Status present(std::size_t i) = 0;

    // Rounds. stage(i): what was drawn since begin_frame(i) waits for commit_round(); the output is
    // not ready until the round completes. commit_round(): puts every staged output on screen in
    // one step -- KMS: one atomic commit carrying every staged plane (the first one a blocking
    // modeset, later ones DRM_MODE_ATOMIC_NONBLOCK | DRM_MODE_PAGE_FLIP_EVENT; each output is ready
    // again after its CRTC's flip event); headless: reads every staged output back, complete on
    // return. A failed commit leaves nothing staged and the outputs showing what they showed. No-op
    // when nothing is staged. The defaults present at once (a backend without rounds).
    [[nodiscard]] virtual Status stage(std::size_t i) { return present(i); }
    [[nodiscard]] virtual Status commit_round() { return {}; }

    // When output `i`'s latest completed present reached the screen, CLOCK_REALTIME nanoseconds:
    // KMS: the kernel's page-flip event timestamp (converted from CLOCK_MONOTONIC); headless: the
    // end of its read-back. nullopt before the first, or when the backend cannot tell.
    [[nodiscard]] virtual std::optional<std::int64_t> presented_ns(std::size_t /*i*/) const { return std::nullopt; }

    // True when output `i` can begin a new frame.
    [[nodiscard]] virtual bool ready(std::size_t i) const = 0;

    // The fd to poll for POLLIN (the DRM fd for KMS), or -1 when the backend completes every
    // present synchronously (headless); poll(2) ignores negative fds, so the kiosk's loop need not
    // special-case it.
    [[nodiscard]] virtual int event_fd() const = 0;

    // Handles pending events without blocking; returns the outputs that became ready.
    [[nodiscard]] virtual Result<std::vector<std::size_t>> dispatch_events() = 0;
};

}  // namespace mogao
