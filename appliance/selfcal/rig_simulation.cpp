// SPDX-License-Identifier: Apache-2.0
// Self-recalibration scenarios on the virtual rig, measured against its ground truth (rig_simulation.h).
#include "appliance/selfcal/rig_simulation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "appliance/autocal/rig_bridge.h"
#include "appliance/warp/response_curve.h"

namespace mogao::selfcal {

namespace {

autocal::DeviceModel device_of(const std::string& id, ImageSize res, const rig::RigIntrinsics& in,
                               const rig::RigPose& pose, autocal::LensFalloff falloff = {}) {
    return {id,
            res,
            in.fx_px,
            in.fy_px,
            in.cx_px,
            in.cy_px,
            in.distortion,
            rig::device_to_screen(pose),
            pose.position_m,
            falloff};
}

void apply_bump(rig::VirtualRig& rig, const Bump& b) {
    rig::RigPose& p = b.device < 0 ? rig.camera.pose : rig.projectors[static_cast<std::size_t>(b.device)].pose;
    p.yaw_deg += b.yaw_deg;
    p.pitch_deg += b.pitch_deg;
    p.roll_deg += b.roll_deg;
    p.position_m += b.shift_m;
}

// Visitors: dark-clothed rectangles standing in front of the screen, each showing the content
// that lands on them displaced (they are nearer the projectors than the screen is).
void occlude(cv::Mat1f& cam, double fraction, cv::RNG& rng) {
    if (fraction <= 0.0) return;
    const double target = fraction * cam.rows * cam.cols;
    double covered = 0.0;
    cv::Mat1b hidden(cam.size(), 0);
    const cv::Mat1f source = cam.clone();
    for (int tries = 0; tries < 200 && covered < target; ++tries) {
        const int w = rng.uniform(cam.cols / 12, cam.cols / 5);
        const int h = rng.uniform(cam.rows / 3, cam.rows);
        const cv::Rect r(rng.uniform(0, cam.cols - w), cam.rows - h, w, h);
        const int dx = rng.uniform(-40, 40);
        for (int y = r.y; y < r.y + r.height; ++y) {
            for (int x = r.x; x < r.x + r.width; ++x) {
                if (hidden(y, x)) continue;
                const int sx = std::clamp(x + dx, 0, cam.cols - 1);
                cam(y, x) = 0.4f * source(y, sx) + 0.01f;
                hidden(y, x) = 1;
                covered += 1.0;
                if (covered >= target) return;
            }
        }
    }
}

// One camera frame of what the wall shows for `content` (linear, clipped to [0, 1] by the
// projectors' signal), with the camera gain and visitors hiding `hidden` of the view.
cv::Mat1f capture(const rig::CameraSimulator& sim, const ScreenCalibration& wall, const cv::Mat1f& content, double gain,
                  double hidden, std::uint64_t visitors_seed, std::uint64_t noise_seed) {
    std::vector<cv::Mat> signals;
    for (const ProjectorCalibration& pc : wall.projectors) signals.emplace_back(projector_signal(pc, content));
    cv::Mat1f cam = sim.capture(signals, noise_seed);
    cam *= gain;
    cv::min(cam, 1.0f, cam);
    cv::RNG rng(visitors_seed);
    occlude(cam, hidden, rng);
    return cam;
}

// Ground truth per projector: the rig and the calibration cut down to projector k alone.
std::vector<autocal::GeometryError> projector_errors(const rig::VirtualRig& truth, const ScreenCalibration& wall) {
    std::vector<autocal::GeometryError> out;
    for (std::size_t k = 0; k < wall.projectors.size(); ++k) {
        rig::VirtualRig one = truth;
        one.projectors = {truth.projectors[k]};
        ScreenCalibration c;
        c.content = wall.content;
        c.projectors = {wall.projectors[k]};
        out.push_back(autocal::measure_geometry(one, c, 8));
    }
    return out;
}

}  // namespace

Bump parse_bump(const rig::VirtualRig& rig, const std::string& text) {
    const auto fail = [&](const std::string& why) {
        throw std::invalid_argument("--bump '" + text + "': " + why +
                                    " (form: proj1:yaw=1deg,pitch=0.2deg,roll=0deg,x=5mm,y=0mm,z=0mm or camera:...)");
    };
    const auto colon = text.find(':');
    if (colon == std::string::npos) fail("no ':'");
    Bump b;
    const std::string who = text.substr(0, colon);
    b.device = -2;
    if (who == "camera") b.device = -1;
    for (std::size_t k = 0; k < rig.projectors.size(); ++k) {
        if (rig.projectors[k].id == who) b.device = static_cast<int>(k);
    }
    if (b.device == -2) fail("unknown device '" + who + "'");
    std::size_t pos = colon + 1;
    while (pos < text.size()) {
        const auto comma = std::min(text.find(',', pos), text.size());
        const std::string part = text.substr(pos, comma - pos);
        pos = comma + 1;
        const auto eq = part.find('=');
        if (eq == std::string::npos) fail("'" + part + "' has no '='");
        const std::string key = part.substr(0, eq);
        std::string value = part.substr(eq + 1);
        double scale = 1.0;
        const auto strip = [&](const std::string& unit, double s) {
            if (value.size() > unit.size() && value.compare(value.size() - unit.size(), unit.size(), unit) == 0) {
                value.resize(value.size() - unit.size());
                scale = s;
                return true;
            }
            return false;
        };
        const bool angle = key == "yaw" || key == "pitch" || key == "roll";
        if (angle) (void)strip("deg", 1.0);
        else if (!strip("mm", 1e-3)) (void)strip("m", 1.0);
        std::size_t used = 0;
        double v = 0.0;
        try {
            v = std::stod(value, &used) * scale;
        } catch (const std::exception&) {
            used = 0;
        }
        if (used != value.size() || value.empty() || !std::isfinite(v)) fail("bad number in '" + part + "'");
        if (key == "yaw") b.yaw_deg = v;
        else if (key == "pitch") b.pitch_deg = v;
        else if (key == "roll") b.roll_deg = v;
        else if (key == "x") b.shift_m.x() = v;
        else if (key == "y") b.shift_m.y() = v;
        else if (key == "z") b.shift_m.z() = v;
        else fail("unknown key '" + key + "'");
    }
    return b;
}

SystemModel models_of_rig(const rig::VirtualRig& rig) {
    SystemModel m;
    // The rig's bow (virtual_rig.h) is ScreenModel's first bow mode exactly.
    m.screen = {rig.screen.radius_m,
                rig.screen.arc_deg,
                rig.screen.bottom_m,
                rig.screen.top_m,
                {rig.screen.bulge_m, 0.0, 0.0, 0.0}};
    m.camera = device_of("camera", rig.camera.resolution, rig.camera.intrinsics, rig.camera.pose);
    for (const rig::RigProjector& p : rig.projectors) {
        m.projectors.push_back(device_of(p.id, p.resolution, p.intrinsics, p.pose, autocal::falloff_of(p)));
    }
    return m;
}

autocal::MeasuredColour colour_of_rig(const rig::VirtualRig& rig, int entries) {
    if (entries < 2 || entries > kMaxResponseEntries) throw std::invalid_argument("colour_of_rig: entries 2..2^20");
    std::array<double, 3> white{};  // W_c
    for (std::size_t c = 0; c < 3; ++c) {
        white[c] = std::numeric_limits<double>::infinity();
        for (const rig::RigProjector& p : rig.projectors) {
            white[c] = std::min(white[c], p.brightness[c] * (1.0 - p.black_level));
        }
    }
    autocal::MeasuredColour out;
    for (const rig::RigProjector& p : rig.projectors) {
        ResponseCurve r;
        std::array<double, 3> black{};
        for (std::size_t c = 0; c < 3; ++c) {
            const double amplitude = p.brightness[c] * (1.0 - p.black_level);
            r.lut[c].resize(static_cast<std::size_t>(entries));
            for (int j = 0; j < entries; ++j) {
                const double x = static_cast<double>(j) / (entries - 1);
                r.lut[c][static_cast<std::size_t>(j)] =
                    static_cast<float>(std::pow(std::min(1.0, x * white[c] / amplitude), 1.0 / p.gamma[c]));
            }
            black[c] = p.brightness[c] * p.black_level / white[c];
        }
        out.responses.push_back(std::move(r));
        out.black.push_back(black);
    }
    return out;
}

cv::Mat1f make_content(ContentKind kind, double t_s, bool moving, std::uint64_t seed) {
    const cv::Size size(960, 540);
    if (kind == ContentKind::plain) return cv::Mat1f(size, 0.3f);
    cv::Mat1f img(size, 0.25f);
    cv::RNG rng(seed);
    if (kind == ContentKind::repetitive) {
        for (int y = 12; y < size.height; y += 24)
            for (int x = 12; x < size.width; x += 24) cv::circle(img, {x, y}, 5, 0.8f, cv::FILLED, cv::LINE_AA);
    } else {
        for (int octave = 8; octave <= 128; octave *= 2) {
            cv::Mat1f noise(octave * 9 / 16 + 1, octave);
            rng.fill(noise, cv::RNG::UNIFORM, -0.5, 0.5);
            cv::Mat1f up;
            cv::resize(noise, up, size, 0, 0, cv::INTER_CUBIC);
            img += up * (0.5 / std::sqrt(static_cast<double>(octave)));
        }
        for (int i = 0; i < 300; ++i) {
            const cv::Point c(rng.uniform(0, size.width), rng.uniform(0, size.height));
            const float v = static_cast<float>(rng.uniform(0.05, 0.95));
            if (i % 3 == 0) cv::circle(img, c, rng.uniform(3, 14), v, cv::FILLED, cv::LINE_AA);
            else if (i % 3 == 1)
                cv::rectangle(img, cv::Rect(c.x, c.y, rng.uniform(4, 30), rng.uniform(4, 30)), v, cv::FILLED);
            else cv::line(img, c, c + cv::Point(rng.uniform(-40, 40), rng.uniform(-40, 40)), v, 2, cv::LINE_AA);
        }
    }
    if (moving) {
        const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 6.0 * t_s, 0, 1, 0);
        cv::warpAffine(img, img, shift, size, cv::INTER_LINEAR, cv::BORDER_WRAP);
    }
    cv::max(img, 0.02f, img);
    cv::min(img, 0.98f, img);
    if (kind == ContentKind::dark) img *= 0.04;
    return img;
}

namespace {

bool is_default_response(const ResponseCurve& r) {
    static const ResponseCurve kDefault = make_gamma_response();
    return r.lut == kDefault.lut;
}

// The calibration's colour: linear x blend + beta (bilinear on its grid like the blend), clamped,
// through the per-channel response LUT (render_output's formula, composite.h): CV_32FC3.
cv::Mat3f coloured_signal(const ProjectorCalibration& pc, const cv::Mat1f& linear) {
    cv::Mat3f beta(linear.size(), cv::Vec3f(0.0f, 0.0f, 0.0f));
    if (!pc.beta.rgb.empty()) {
        const cv::Mat3f grid(pc.beta.size.height, pc.beta.size.width,
                             reinterpret_cast<cv::Vec3f*>(const_cast<float*>(pc.beta.rgb.data())));
        cv::resize(grid, beta, linear.size(), 0, 0, cv::INTER_LINEAR);
    }
    cv::Mat3f out(linear.size());
    for (int y = 0; y < linear.rows; ++y) {
        for (int x = 0; x < linear.cols; ++x) {
            for (int c = 0; c < 3; ++c) {
                out(y, x)[c] = apply_response(pc.response, c, linear(y, x) + beta(y, x)[c]);
            }
        }
    }
    return out;
}

}  // namespace

cv::Mat projector_signal(const ProjectorCalibration& pc, const cv::Mat1f& content) {
    const ImageSize g = pc.warp.size;
    cv::Mat1f gu(g.height, g.width);
    cv::Mat1f gv(g.height, g.width);
    for (int y = 0; y < g.height; ++y) {
        for (int x = 0; x < g.width; ++x) {
            const std::size_t i = 2 * (static_cast<std::size_t>(y) * g.width + x);
            const float u = pc.warp.uv[i];
            const float v = pc.warp.uv[i + 1];
            // No content: far outside the frame (black), after the bilinear resize too.
            gu(y, x) = std::isfinite(u) ? u * static_cast<float>(content.cols) - 0.5f : -1e4f;
            gv(y, x) = std::isfinite(v) ? v * static_cast<float>(content.rows) - 0.5f : -1e4f;
        }
    }
    const cv::Size out(pc.output.width, pc.output.height);
    cv::Mat1f mx, my, blend;
    // cv::resize's bilinear maps output centre x + 0.5 to grid position (x + 0.5) * M / W - 0.5,
    // clamped at the edges: exactly sample_warp's convention (projector_calibration.h).
    cv::resize(gu, mx, out, 0, 0, cv::INTER_LINEAR);
    cv::resize(gv, my, out, 0, 0, cv::INTER_LINEAR);
    const cv::Mat1f bl(pc.blend.size.height, pc.blend.size.width, const_cast<float*>(pc.blend.weight.data()));
    cv::resize(bl, blend, out, 0, 0, cv::INTER_LINEAR);
    cv::Mat1f signal;
    cv::remap(content, signal, mx, my, cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0.0);
    signal = signal.mul(blend);
    if (pc.beta.rgb.empty() && is_default_response(pc.response)) {
        cv::max(signal, 0.0f, signal);
        cv::min(signal, 1.0f, signal);
        cv::pow(signal, 1.0 / 2.2, signal);  // the response calibration_from_models builds: gamma 2.2
        return signal;
    }
    return coloured_signal(pc, signal);
}

namespace {

// A starting model must describe the rig it watches: the same devices at the same resolutions.
void check_start_model(const SystemModel& m, const rig::VirtualRig& truth) {
    const auto size_text = [](ImageSize s) { return std::to_string(s.width) + "x" + std::to_string(s.height); };
    if (m.projectors.size() != truth.projectors.size()) {
        throw std::invalid_argument("simulate: the starting models have " + std::to_string(m.projectors.size()) +
                                    " projectors, the rig " + std::to_string(truth.projectors.size()));
    }
    if (m.camera.resolution != truth.camera.resolution) {
        throw std::invalid_argument(
            "simulate: the starting models' camera is " + size_text(m.camera.resolution) + ", the scaled rig's " +
            size_text(truth.camera.resolution) +
            " (calibrate at the same scale: mogao-calibrate-sim rig --scale equal to --camera-scale)");
    }
    for (std::size_t k = 0; k < m.projectors.size(); ++k) {
        if (m.projectors[k].resolution != truth.projectors[k].resolution) {
            throw std::invalid_argument(
                "simulate: the starting models' projector " + std::to_string(k) + " is " +
                size_text(m.projectors[k].resolution) + ", the scaled rig's " +
                size_text(truth.projectors[k].resolution) +
                " (calibrate at the same scale: mogao-calibrate-sim rig --scale equal to --projector-scale)");
        }
    }
}

// One monitored frame: the content as the camera films it (with the options' exposure jitter and occluding
// visitors), or the fallback pattern pair (two refreshes 1/60 s apart, same exposure, the visitors where they were),
// handed to the self-calibrator.
StepResult step_on_frame(SelfCalibrator& sc, const rig::CameraSimulator& sim, const ScreenCalibration& wall,
                         const cv::Mat1f& content, const SimulationOptions& o, cv::RNG& rng, int i, double t) {
    const double gain = 1.0 + rng.uniform(-o.exposure_jitter, o.exposure_jitter + 1e-12);
    const double hidden =
        o.occlusion_max > o.occlusion ? rng.uniform(o.occlusion, std::min(0.9, o.occlusion_max)) : o.occlusion;
    const std::uint64_t frame_seed = static_cast<std::uint64_t>(i) + o.seed * 100000;
    const std::optional<cv::Mat1f> plus = sc.pattern_for_refresh(0, content.size());
    if (plus) {
        // The pattern pair: two refreshes 1/60 s apart, same exposure, the visitors where they were.
        const std::uint64_t visitors = rng.next();
        cv::Mat1f shown_plus;
        cv::Mat1f shown_minus;
        cv::add(content, *plus, shown_plus);
        cv::add(content, *sc.pattern_for_refresh(1, content.size()), shown_minus);
        const cv::Mat1f cam_plus = capture(sim, wall, shown_plus, gain, hidden, visitors, frame_seed);
        const cv::Mat1f cam_minus = capture(sim, wall, shown_minus, gain, hidden, visitors, frame_seed + (1ULL << 40));
        return sc.step_pattern(content, cam_plus, cam_minus, t);
    }
    return sc.step(content, capture(sim, wall, content, gain, hidden, rng.next(), frame_seed), t);
}

// The report's timings after the first bump (`since_bump` seconds): the error when it struck, when the drift
// was detected and when a correction brought the error under the threshold.
void record_after_bump(SimulationReport& rep, const StepResult& r, const autocal::GeometryError& g, double since_bump,
                       const SimulationOptions& o, bool& measured_before) {
    if (!measured_before) {
        rep.error_before_px = g.mean_px;
        measured_before = true;
    }
    if (!rep.detected_after_s && r.status.state != SelfcalState::calibrated) rep.detected_after_s = since_bump;
    if (!rep.corrected_after_s && rep.corrections > 0 && r.status.state == SelfcalState::calibrated &&
        g.mean_px < o.error_threshold_px) {
        rep.corrected_after_s = since_bump;
    }
}

}  // namespace

SimulationReport simulate(const rig::VirtualRig& input, const SimulationOptions& o) {
    if (!(o.rate_hz > 0.0) || o.frames < 1 || !(o.occlusion >= 0.0 && o.occlusion <= 0.9) ||
        !(o.exposure_jitter >= 0.0 && o.exposure_jitter < 1.0) || o.truth_every < 1) {
        throw std::invalid_argument(
            "simulate: rate_hz > 0, frames >= 1, occlusion in [0, 0.9], exposure_jitter in [0, 1), truth_every >= 1");
    }
    rig::VirtualRig truth = autocal::scaled_rig(input, o.projector_scale, o.camera_scale);
    for (const Bump& b : o.bumps) {
        if (b.device < -1 || b.device >= static_cast<int>(truth.projectors.size())) {
            throw std::invalid_argument("simulate: bump device out of range");
        }
    }
    const SystemModel model = o.start_model ? *o.start_model : models_of_rig(truth);
    check_start_model(model, truth);
    SimulationReport rep;
    ScreenCalibration wall =
        autocal::calibration_from_models(model.projectors, model.screen, {1920, 1080}, o.selfcal.build);
    if (o.measured_colour)
        (void)autocal::apply_measured_colour(colour_of_rig(truth), model.projectors, model.screen, wall);
    rep.initial_calibration = wall;
    SelfCalibrator sc(model, wall, o.selfcal);
    auto sim = std::make_unique<rig::CameraSimulator>(truth);
    std::vector<bool> applied(o.bumps.size(), false);
    double first_bump = o.bumps.empty() ? std::nan("") : o.bumps.front().at_s;
    for (const Bump& b : o.bumps) first_bump = std::min(first_bump, b.at_s);
    cv::RNG rng(o.seed);
    double cpu = 0.0;
    bool measured_before = false;
    autocal::GeometryError g;
    for (int i = 0; i < o.frames; ++i) {
        const double t = i / o.rate_hz;
        bool changed = false;
        for (std::size_t b = 0; b < o.bumps.size(); ++b) {
            if (!applied[b] && t >= o.bumps[b].at_s) {
                apply_bump(truth, o.bumps[b]);
                applied[b] = true;
                changed = true;
            }
        }
        if (changed) sim = std::make_unique<rig::CameraSimulator>(truth);
        const cv::Mat1f content = make_content(o.content, t, o.moving_content, o.seed);
        const StepResult r = step_on_frame(sc, *sim, wall, content, o, rng, i, t);
        if (r.calibration) wall = *r.calibration;
        for (const std::string& line : r.journal) rep.journal.push_back(line);
        if (r.status.state == SelfcalState::correcting &&
            (rep.frames.empty() || rep.frames.back().state != SelfcalState::correcting)) {
            ++rep.corrections;
        }
        if (r.status.state == SelfcalState::drift_detected &&
            (rep.frames.empty() || rep.frames.back().state != SelfcalState::drift_detected)) {
            ++rep.detections;
        }
        if (i % o.truth_every == 0 || i + 1 == o.frames || changed || r.calibration || rep.frames.empty()) {
            g = autocal::GeometryError{};  // the worst projector's
            for (const autocal::GeometryError& e : projector_errors(truth, wall)) {
                if (e.mean_px >= g.mean_px) g = e;
            }
        }
        if (rep.frames.empty()) rep.start_error_px = g.mean_px;
        rep.frames.push_back({t, r.status.state, r.status.waiting, g.mean_px, r.cpu_ms, r.status.text()});
        rep.waiting_frames += r.status.waiting ? 1 : 0;
        cpu += r.cpu_ms;
        rep.final_error_px = g.mean_px;
        rep.final_p95_px = g.p95_px;
        rep.final_state = r.status.state;
        if (std::isfinite(first_bump) && t >= first_bump)
            record_after_bump(rep, r, g, t - first_bump, o, measured_before);
    }
    rep.mean_cpu_ms = cpu / o.frames;
    rep.final_calibration = std::move(wall);
    rep.final_rig = std::move(truth);
    return rep;
}

}  // namespace mogao::selfcal
