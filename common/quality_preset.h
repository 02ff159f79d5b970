// SPDX-License-Identifier: Apache-2.0
// The quality presets, one table for both sides: what an appliance asks for per frame (the
// request's Quality) and how the farm schedules a session's frames in serve mode.
//
//   interactive  fluid motion first: 1 spp and one bounce (0 bounces is by far the largest error in
//                the closed grotto), the frame-time target shrinks moving frames, still views
//                refine progressively (a visitor who stops sees the wall converge)
//   balanced     4 spp, two bounces, a slower frame-time target
//   exhibit      what a curator wants when visitors stop: 64 spp, four bounces, no frame-time
//                target (every request at its full size), refinement to many samples
// No preset traces AO rays: in the grotto they buy at most 0.1 dB (docs/quality.md).
//
// The figures behind each choice (time against error for spp, bounces, AO, resolution scale and
// JPEG quality, against converged references) are in docs/quality.md; the presets' own measured
// frame time and PSNR are there too. An explicit flag or key always overrides its preset's value.
//
// Errors: quality_preset() returns nullptr for an unknown name; callers name the flag or key and
// quality_preset_names() in their message.
#pragma once

#include <span>
#include <string>
#include <string_view>

#include "common/view_request.h"

namespace mogao {

struct QualityPreset {
    std::string_view name;
    Quality request;           // spp, bounces, AO, area-light samples, scale, JPEG quality
    double frame_time_ms = 0;  // serve: per-session frame-time target, ms (0 = none)
    bool progressive = true;   // serve: still views accumulate samples over requests
    int converged_spp = 1024;  // serve: a still view stops refining at this many samples
    // serve: the à-trous denoiser (renderfarm/denoise) on every frame of few samples (moving frames,
    // a still view's first passes; renderfarm/farm/live_frames.h). `mogao-farm render` does not
    // apply it.
    bool denoise = false;
    // serve: moving frames from the render ranks' radiance cache (renderfarm/trace/radiance_cache.h;
    // biased, much cheaper; still views refine without it).
    bool radiance_cache = false;
    // serve: a session whose requests come less often than the frame-time target has its frames take the
    // time its pace gives them (renderfarm/farm/live_frames.h, LiveOptions::follow_request_pace).
    bool follow_request_pace = false;
    // Measured in docs/quality.md but not applied by the farm yet: JPEG 4:4:4 instead of the
    // link's 4:2:0.
    bool chroma_444 = false;
};

// Every preset, from the fastest to the most accurate.
[[nodiscard]] std::span<const QualityPreset> quality_presets();
// The preset called `name`, or nullptr.
[[nodiscard]] const QualityPreset* quality_preset(std::string_view name);
// "interactive, balanced, exhibit" (for error messages and --help).
[[nodiscard]] std::string quality_preset_names();

}  // namespace mogao
