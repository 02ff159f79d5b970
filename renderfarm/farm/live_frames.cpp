// SPDX-License-Identifier: Apache-2.0
#include "renderfarm/farm/live_frames.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/request_limits.h"
#include "renderfarm/trace/film.h"

namespace mogao {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

LiveFrames::LiveFrames(FrameDispatcher& farm, LiveOptions options)
    : LiveFrames([&farm](const ViewRequest& view, std::uint64_t stream,
                         PackedPixels format) { return farm.render(view, stream, format); },
                 std::move(options), farm.settings().exposure, farm.settings().tone_map) {}

LiveFrames::LiveFrames(FrameSource source, LiveOptions options, float exposure, ToneMap tone_map)
    : source_(std::move(source)), options_(std::move(options)), exposure_(exposure), tone_map_(tone_map) {
    if (!source_) throw std::invalid_argument("LiveFrames: no frame source");
    if (options_.frame_time_s < 0) throw std::invalid_argument("LiveOptions.frame_time_s must be >= 0");
    if (options_.converged_spp < 1) throw std::invalid_argument("LiveOptions.converged_spp must be >= 1");
    if (!(options_.pace_share > 0 && options_.pace_share < 1))
        throw std::invalid_argument("LiveOptions.pace_share must be in (0, 1)");
    if (!(options_.max_pace_factor >= 1)) throw std::invalid_argument("LiveOptions.max_pace_factor must be >= 1");
    if (options_.still_first_pass_spp < 1 || options_.still_second_pass_spp < 1 || options_.still_pass_spp < 1)
        throw std::invalid_argument(
            "LiveOptions.still_first_pass_spp, still_second_pass_spp and still_pass_spp must be >= 1");
    if (options_.shading_one_in < request_limits::kShadingOneIn.min ||
        options_.shading_one_in > request_limits::kShadingOneIn.max)
        throw std::invalid_argument("LiveOptions.shading_one_in must be in " + request_limits::kShadingOneIn.text());
    options_.controller.target_seconds = options_.frame_time_s > 0 ? options_.frame_time_s : 1.0;
    (void)FrameTimeController(options_.controller);  // validates the controller's settings now
    if (options_.denoise_max_spp < 1) throw std::invalid_argument("LiveOptions.denoise_max_spp must be >= 1");
    const RgbFloatImage probe(ImageSize{1, 1});
    if (Status st = validate_denoise_input(probe, GuideBuffers(probe.size), options_.denoise_params); !st.ok())
        throw std::invalid_argument("LiveOptions.denoise_params: " + st.error().message);
    AtrousParams blended = options_.denoise_params;
    blended.iterations = options_.blended_denoise_iterations;
    if (Status st = validate_denoise_input(probe, GuideBuffers(probe.size), blended); !st.ok())
        throw std::invalid_argument("LiveOptions.blended_denoise_iterations: " + st.error().message);
    try {
        check_temporal_params(options_.temporal_params);
    } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(std::string("LiveOptions.temporal_params: ") + e.what());
    }
}

LiveFrames::Session& LiveFrames::session(std::uint64_t id) {
    auto found = sessions_.find(id);
    if (found == sessions_.end()) {
        if (sessions_.size() >= std::max<std::size_t>(1, options_.max_sessions)) {
            sessions_.erase(std::min_element(sessions_.begin(), sessions_.end(), [](const auto& a, const auto& b) {
                return a.second.last_used < b.second.last_used;
            }));
        }
        found = sessions_.try_emplace(id).first;
        if (options_.frame_time_s > 0) found->second.controller.emplace(options_.controller);
    }
    found->second.last_used = ++frames_;
    return found->second;
}

std::size_t LiveFrames::active_sessions(std::uint64_t current, std::chrono::steady_clock::time_point now) const {
    std::size_t n = 0;
    for (const auto& [id, s] : sessions_) {
        if (id == current || (s.handed_back && now - *s.handed_back <= kActiveWindow)) ++n;
    }
    return std::max<std::size_t>(n, 1);
}

double LiveFrames::frame_share_seconds(std::uint64_t current) const {
    if (!options_.share_frame_time || options_.frame_time_s <= 0) return 0.0;
    const auto now = Clock::now();
    std::vector<double> others;
    for (const auto& [id, s] : sessions_) {
        if (id != current && s.handed_back && now - *s.handed_back <= kActiveWindow && s.recent_seconds > 0)
            others.push_back(s.recent_seconds);
    }
    if (others.empty()) return 0.0;
    std::nth_element(others.begin(), others.begin() + others.size() / 2, others.end());
    return std::max(options_.frame_time_s, others[others.size() / 2]);
}

double LiveFrames::paced_target(Session& s, const ViewRequest& request, double gap_seconds,
                                Clock::time_point now) const {
    const std::size_t sessions = active_sessions(request.session, now);
    double target = options_.frame_time_s;
    if (options_.share_frame_time) target /= double(sessions);
    // A farm shared by several sessions is busy with the others between one's frames: their wait is no idle time.
    if (!options_.follow_request_pace || sessions > 1) return target;
    if (s.last_request && request.frame_id > s.last_request->frame_id && s.last_request->request_time_ns > 0 &&
        request.request_time_ns > s.last_request->request_time_ns) {
        const double period = 1e-9 * static_cast<double>(request.request_time_ns - s.last_request->request_time_ns) /
                              static_cast<double>(request.frame_id - s.last_request->frame_id);
        s.pace.note(period, gap_seconds, options_.pace_share);
    }
    return s.pace.target(target, options_.pace_share, options_.max_pace_factor);
}

// Whether `request` repeats the session's previous view: a still view, accumulated.
bool LiveFrames::is_still(const Session& s, const ViewRequest& request) const {
    return options_.progressive && s.last_request && same_view(request, *s.last_request);
}

double LiveFrames::scene_time_s() const {
    if (options_.scene_clock) return options_.scene_clock();
    return std::chrono::duration<double>(Clock::now() - created_).count();
}

// What the session learnt under other lights is dropped: its temporal history and its still view's
// samples (a still view then starts again from its first pass).
void LiveFrames::follow_lighting(Session& s, double time_s) {
    if (!options_.lighting) return;
    std::vector<float> state = options_.lighting(time_s);
    if (s.lighting && *s.lighting != state) {
        s.accumulation.reset();
        s.temporal.clear();
    }
    s.lighting = std::move(state);
}

// The view to trace for `request`: still views at the request's own scale (to accumulate), moving
// ones at the controller's choice; the pass's frame_id when it continues an accumulation.
ViewRequest LiveFrames::plan(Session& s, const ViewRequest& request, FrameChoice& choice) const {
    choice = {};
    choice.resolution_scale = request.quality.resolution_scale;
    choice.spp = request.quality.spp;
    if (s.controller) choice = s.controller->choose(request);
    const bool still = is_still(s, request);
    if (still) {  // accumulated at the request's own scale and depth
        choice.resolution_scale = request.quality.resolution_scale;
        choice.bounces = -1;
        choice.bounce_work = 1.0;
    }
    ViewRequest view = request;
    view.quality.resolution_scale = choice.resolution_scale;
    view.quality.spp = choice.spp;
    if (choice.bounces >= 0) view.quality.max_bounces = choice.bounces;
    if (options_.progressive && s.accumulation.continues(view)) {
        const int pass_spp = s.accumulation.passes() == 1 ? options_.still_second_pass_spp : options_.still_pass_spp;
        choice.spp = std::max(choice.spp, pass_spp);
        view.quality.spp = choice.spp;
        view.frame_id = pass_frame_id(s.accumulation.first_frame_id(), s.accumulation.passes());
    } else {
        view.radiance_cache = options_.radiance_cache && !still;
        plan_sparse(s, view);
        if (still && options_.progressive) {
            choice.spp = std::max(choice.spp, options_.still_first_pass_spp);
            view.quality.spp = choice.spp;
        }
    }
    return view;
}

// A cached moving frame shades one pixel in shading_one_in when its history can supply the rest
// (display() blends every filtered moving frame with it); the pattern's phase moves on with each such frame.
void LiveFrames::plan_sparse(Session& s, ViewRequest& view) const {
    if (!view.radiance_cache || !options_.denoise || !options_.temporal || s.temporal.empty()) return;
    if (view.quality.spp > options_.denoise_max_spp) return;  // not filtered, so not blended: shown as traced
    if (options_.shading_one_in == 1) return;
    view.shading_one_in = options_.shading_one_in;
    view.shading_phase = static_cast<int>(s.sparse_frames++ % static_cast<std::uint64_t>(options_.shading_one_in));
}

// A pass joins the session's accumulation unless it was cut short or traced with the (biased) cache.
bool LiveFrames::accumulates(const LiveFrame& frame) const {
    return options_.progressive && frame.stats.tiles_cut == 0 && !frame.rendered.radiance_cache;
}

Rgb8Image LiveFrames::to_display(const RgbFloatImage& radiance) const {
    Rgb8Image out(radiance.size);
    // Every core of the admin: the render ranks wait for the next request meanwhile.
    to_srgb8(radiance, PixelRect::whole(radiance.size), exposure_, out, tone_map_, 0);
    return out;
}

// Renders `request`'s pass (the guides too on the first pass of a view when denoising) and adds it
// to the session's accumulation; `radiance` gets the frame to display in linear light, or stays
// empty when the source sent sRGB8 (frame.image).
void LiveFrames::dispatch(Session& s, const ViewRequest& request, int spp, LiveFrame& frame, RgbFloatImage& radiance) {
    const bool continues = options_.progressive && s.accumulation.continues(frame.rendered);
    const bool guided = options_.denoise && !continues;  // the guides are the view's, not the pass's
    const PackedPixels format = guided                 ? PackedPixels::linear_guided
                                : options_.progressive ? PackedPixels::linear
                                                       : PackedPixels::srgb8;
    const std::uint64_t stream = options_.per_session_maps ? request.session : 0;
    DispatchedFrame f = source_(frame.rendered, stream, format);
    if (guided && f.guides.size != f.radiance.size) {
        throw std::runtime_error("denoise: the frame's guides are " + std::to_string(f.guides.size.width) + "x" +
                                 std::to_string(f.guides.size.height) + ", its radiance " +
                                 std::to_string(f.radiance.size.width) + "x" + std::to_string(f.radiance.size.height));
    }
    frame.stats = std::move(f.stats);
    frame.samples = spp;
    if (accumulates(frame)) {
        s.accumulation.add(frame.rendered, f.radiance);
    } else if (guided || options_.progressive) {  // a cut pass is shown alone, never accumulated
        radiance = std::move(f.radiance);
    } else {
        frame.image = std::move(f.image);
    }
    if (guided) s.guides = std::move(f.guides);
}

// The frame served: `radiance` filtered when denoising and few samples are in it, then displayed.
void LiveFrames::display(Session& s, const RgbFloatImage& radiance, LiveFrame& frame) {
    if (!options_.denoise || frame.samples > options_.denoise_max_spp || s.guides.size != radiance.size) {
        frame.image = to_display(radiance);
        return;
    }
    const auto start = Clock::now();
    const RgbFloatImage* noisy = &radiance;
    RgbFloatImage blended;
    const std::vector<float>* temporal_variance = nullptr;
    AtrousParams params = options_.denoise_params;
    if (options_.temporal && !frame.still) {
        params.iterations = options_.blended_denoise_iterations;
        blended = s.temporal.accumulate(radiance, s.guides, make_camera_setup(frame.rendered, radiance.size),
                                        options_.temporal_params, &frame.temporal, frame.rendered.shading_one_in);
        noisy = &blended;
        if (options_.temporal_variance) temporal_variance = &s.temporal.luminance_variance();
        frame.temporal_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    }
    // A still view's accumulation of two passes or more brings its own noise, measured from the
    // passes' spread: the filter then does less as samples come in, instead of blurring as much at
    // 64 spp as at 1 (the spatial estimate also counts shading and texture as noise).
    const RgbFloatImage variance = frame.passes >= 2 ? s.accumulation.variance_of_mean() : RgbFloatImage{};
    const bool measured = !variance.pixels.empty();  // the passes' spread, where there is one, wins
    RgbFloatImage filtered;
    if (Status st = denoiser_.run(*noisy, s.guides, params, filtered, measured ? &variance : nullptr,
                                  measured ? nullptr : temporal_variance);
        !st.ok())
        throw std::runtime_error(st.error().message);
    frame.image = to_display(filtered);
    frame.denoised = true;
    frame.denoise_seconds = std::chrono::duration<double>(Clock::now() - start).count();
}

LiveFrame LiveFrames::render(const ViewRequest& request) {
    const auto start = Clock::now();
    Session& s = session(request.session);
    FrameChoice choice;
    LiveFrame frame;
    if (s.handed_back) frame.gap_seconds = std::chrono::duration<double>(start - *s.handed_back).count();
    if (s.controller) s.controller->set_target_seconds(paced_target(s, request, frame.gap_seconds, start));
    ViewRequest timed = request;
    timed.scene_time_s = scene_time_s();
    follow_lighting(s, timed.scene_time_s);
    frame.still = is_still(s, request);
    frame.rendered = plan(s, timed, choice);
    const bool continues = options_.progressive && s.accumulation.continues(frame.rendered);
    RgbFloatImage radiance;
    if (continues && s.accumulation.samples() >= options_.converged_spp) {
        frame.rendered_now = false;
    } else {
        dispatch(s, request, choice.spp, frame, radiance);
    }
    if (accumulates(frame)) {
        radiance = s.accumulation.mean();
        frame.samples = s.accumulation.samples();
        frame.passes = s.accumulation.passes();
    }
    if (!radiance.pixels.empty()) display(s, radiance, frame);
    frame.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    if (s.controller && frame.rendered_now) s.controller->observe(choice, frame.seconds, frame.gap_seconds);
    if (frame.rendered_now) {
        constexpr double kWeight = 0.3;  // of the newest frame: a few frames' memory
        s.recent_seconds =
            s.recent_seconds > 0 ? (1 - kWeight) * s.recent_seconds + kWeight * frame.seconds : frame.seconds;
    }
    s.last_request = request;
    s.handed_back = Clock::now();
    return frame;
}

}  // namespace mogao
