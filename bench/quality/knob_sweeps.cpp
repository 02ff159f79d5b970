// SPDX-License-Identifier: Apache-2.0
#include "bench/quality/knob_sweeps.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "bench/quality/image_metrics.h"
#include "common/jpeg_codec.h"
#include "common/quality_preset.h"
#include "common/thread_clock.h"
#include "renderfarm/denoise/atrous_filter.h"
#include "renderfarm/denoise/frame_error.h"
#include "renderfarm/denoise/guide_pass.h"
#include "renderfarm/trace/render_timing.h"

namespace mogao::quality {

namespace {

// Compares frames with the reference and records rows.
class Recorder {
public:
    Recorder(const Scene& scene, const QualityView& view, const RgbFloatImage& reference)
        : scene_(scene),
          view_(view),
          reference_(reference),
          reference_8_(display_frame(reference, scene.exposure, scene.tone_map)) {}

    void linear(const std::string& knob, const std::string& value, int spp, double seconds, const RgbFloatImage& frame,
                bool is_default, const std::string& note = "") {
        const RgbFloatImage& full =
            frame.size.width == reference_.size.width ? frame : (scaled_ = resize_bilinear(frame, reference_.size));
        const Rgb8Image shown = display_frame(full, scene_.exposure, scene_.tone_map);
        rows.push_back({view_.name, knob, value, spp, 1e3 * seconds, display_psnr_db(shown, reference_8_),
                        relative_mse(full, reference_), ssim_luminance(shown, reference_8_), is_default, note});
        print(rows.back());
    }
    void display(const std::string& knob, const std::string& value, int spp, double seconds, const Rgb8Image& shown,
                 double relmse, bool is_default, const std::string& note) {
        rows.push_back({view_.name, knob, value, spp, 1e3 * seconds, display_psnr_db(shown, reference_8_), relmse,
                        ssim_luminance(shown, reference_8_), is_default, note});
        print(rows.back());
    }
    const Rgb8Image& reference_display() const { return reference_8_; }
    const RgbFloatImage& reference() const { return reference_; }
    std::vector<Measurement> rows;

private:
    static void print(const Measurement& m) {
        std::fprintf(stderr, "  %-5s %-22s %-8s spp %-3d %9.1f ms  PSNR %6.2f dB  relMSE %.4g  SSIM %.4f %s\n",
                     m.view.c_str(), m.knob.c_str(), m.value.c_str(), m.spp, m.ms, m.psnr_db, m.relmse, m.ssim,
                     m.note.c_str());
    }
    const Scene& scene_;
    const QualityView& view_;
    const RgbFloatImage& reference_;
    Rgb8Image reference_8_;
    RgbFloatImage scaled_;
};

struct Context {
    const Scene& scene;
    Renderer& renderer;
    const QualityView& view;
    const SweepOptions& options;
    Recorder& out;

    TimedFrame render(const Quality& q) const {
        ViewRequest r = view.request;
        r.quality = q;
        return render_fastest_of(renderer, r, options.reps);
    }
};

Quality with_spp(int spp) {
    Quality q;
    q.spp = spp;
    return q;
}

std::string fmt(double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%g", v);
    return b;
}

void spp_series(const Context& c) {
    for (int spp = 1; spp <= c.options.max_spp; spp *= 2) {
        const TimedFrame f = c.render(with_spp(spp));
        c.out.linear("spp", std::to_string(spp), spp, f.seconds, f.image, spp == 1);
    }
    for (int spp = 1; spp <= c.options.max_reference_knob_spp; spp *= 2) {
        Quality q = with_spp(spp);
        q.max_bounces = kReferenceBounces;
        q.ao_samples = 1;
        const TimedFrame f = c.render(q);
        c.out.linear("spp (reference knobs)", std::to_string(spp), spp, f.seconds, f.image, false,
                     std::to_string(kReferenceBounces) + " bounces, AO 1");
    }
}

void path_knobs(const Context& c, int spp) {
    const std::string at = " @" + std::to_string(spp) + " spp";
    for (int b = 0; b <= 4; ++b) {
        Quality q = with_spp(spp);
        q.max_bounces = b;
        const TimedFrame f = c.render(q);
        c.out.linear("bounces" + at, std::to_string(b), spp, f.seconds, f.image, b == 0);
    }
    for (int ao : {0, 1, 2, 4, 8, 16}) {
        Quality q = with_spp(spp);
        q.ao_samples = ao;
        const TimedFrame f = c.render(q);
        c.out.linear("AO samples" + at, std::to_string(ao), spp, f.seconds, f.image, ao == 0);
    }
    for (double s : {0.25, 0.5, 0.75, 1.0}) {
        Quality q = with_spp(spp);
        q.resolution_scale = s;
        const TimedFrame f = c.render(q);
        c.out.linear("resolution scale" + at, fmt(s), spp, f.seconds, f.image, s == 1.0,
                     s < 1.0 ? "bilinear upscale" : "");
    }
    for (const bool legacy : {true, false}) {
        RendererOptions o;
        o.legacy_light_sampling = legacy;
        c.renderer.set_path_options(o);
        const TimedFrame f = c.render(with_spp(spp));
        c.out.linear("light selection" + at, legacy ? "one-per-light" : "power", spp, f.seconds, f.image, legacy);
    }
    c.renderer.set_path_options(RendererOptions{});
}

// Render + guide pass + à-trous filter (renderfarm/denoise), one thread; best of reps.
TimedFrame denoised(const Context& c, GuidePass& pass, const Quality& q) {
    ViewRequest r = c.view.request;
    r.quality = q;
    TimedFrame best{{}, 1e300};
    for (int k = 0; k < c.options.reps; ++k) {
        const TimedFrame raw = render_fastest_of(c.renderer, r, 1);
        const double t0 = thread_cpu_seconds();
        Result<GuideBuffers> guides = pass.render_frame(r);
        if (!guides.ok()) throw std::runtime_error(guides.error().message);
        Result<RgbFloatImage> out = denoise_atrous(raw.image, *guides);
        if (!out.ok()) throw std::runtime_error(out.error().message);
        const double seconds = raw.seconds + thread_cpu_seconds() - t0;
        if (seconds < best.seconds) best = {std::move(*out), seconds};
    }
    return best;
}

// The denoiser at the default knobs (0 bounces: bias-dominated in a closed grotto) and at 2 bounces,
// with the raw 2-bounce series beside it.
void denoiser_series(const Context& c) {
    GuidePass pass(c.scene, "threads=1");
    for (int bounces : {0, 2}) {
        const std::string suffix = bounces == 0 ? "" : " (2 bounces)";
        for (int spp = 1; spp <= 16; spp *= 2) {
            Quality q = with_spp(spp);
            q.max_bounces = bounces;
            if (bounces > 0) {
                const TimedFrame raw = c.render(q);
                c.out.linear("spp" + suffix, std::to_string(spp), spp, raw.seconds, raw.image, false);
            }
            const TimedFrame f = denoised(c, pass, q);
            c.out.linear("denoiser on" + suffix, std::to_string(spp), spp, f.seconds, f.image, false,
                         "render + guides + filter");
        }
    }
}

// JPEG of the reference's display frame alone: the codec's own error, apart from render noise.
void jpeg_series(const Context& c) {
    JpegEncoder encoder;
    JpegDecoder decoder;
    const Rgb8Image& ref8 = c.out.reference_display();
    const std::pair<Subsampling, const char*> modes[] = {
        {Subsampling::yuv420, "4:2:0"}, {Subsampling::yuv422, "4:2:2"}, {Subsampling::yuv444, "4:4:4"}};
    for (const auto& [mode, label] : modes)
        for (int q : {50, 60, 70, 75, 80, 85, 90, 95, 100}) {
            double best = 1e300;
            std::vector<std::uint8_t> bytes;
            for (int k = 0; k < std::max(3, c.options.reps); ++k) {
                const double t0 = thread_cpu_seconds();
                bytes = encoder.encode(ref8, q, mode);
                best = std::min(best, thread_cpu_seconds() - t0);
            }
            c.out.display(std::string("JPEG ") + label, std::to_string(q), 0, best, decoder.decode(bytes), std::nan(""),
                          q == 85 && mode == Subsampling::yuv420, std::to_string(bytes.size()) + " bytes");
        }
}

// The frame rendered as T x T tiles one after another: time only; the image must be bit-identical.
void tile_series(const Context& c) {
    ViewRequest r = c.view.request;
    r.quality = with_spp(1);
    const TimedFrame whole = render_fastest_of(c.renderer, r, 1);
    const ImageSize size = whole.image.size;
    for (int tile : {8, 16, 32, 64, 0}) {
        RgbFloatImage frame(size);
        double best = 1e300;
        for (int k = 0; k < std::max(2, c.options.reps); ++k) {
            c.renderer.begin_frame(r);
            const double t0 = thread_cpu_seconds();
            const int tw = tile > 0 ? tile : size.width, th = tile > 0 ? tile : size.height;
            for (int y = 0; y < size.height; y += th)
                for (int x = 0; x < size.width; x += tw)
                    c.renderer.render({x, y, std::min(size.width, x + tw), std::min(size.height, y + th)}, frame);
            best = std::min(best, thread_cpu_seconds() - t0);
        }
        const bool same = std::memcmp(frame.pixels.data(), whole.image.pixels.data(), frame.pixels.size() * 4) == 0;
        c.out.linear("tile size", tile > 0 ? std::to_string(tile) : "whole", 1, best, frame, tile == 16,
                     same ? "bit-identical to the whole frame" : "DIFFERS from the whole frame");
    }
}

void preset_rows(const Context& c) {
    GuidePass pass(c.scene, "threads=1");
    JpegEncoder encoder;
    JpegDecoder decoder;
    for (const QualityPreset& p : quality_presets()) {  // common/quality_preset.h: the farm's own table
        const Quality q = p.request;
        ViewRequest r = c.view.request;
        r.quality = q;
        TimedFrame f = render_fastest_of(c.renderer, r, 1);
        double seconds = f.seconds;
        const double t0 = thread_cpu_seconds();
        if (p.denoise) {
            Result<GuideBuffers> guides = pass.render_frame(r);
            if (!guides.ok()) throw std::runtime_error(guides.error().message);
            Result<RgbFloatImage> out = denoise_atrous(f.image, *guides);
            if (!out.ok()) throw std::runtime_error(out.error().message);
            f.image = std::move(*out);
        }
        RgbFloatImage full = f.image.size.width == c.out.reference().size.width
                                 ? f.image
                                 : resize_bilinear(f.image, c.out.reference().size);
        const std::vector<std::uint8_t> bytes =
            encoder.encode(display_frame(full, c.scene.exposure, c.scene.tone_map), q.jpeg_quality,
                           p.chroma_444 ? Subsampling::yuv444 : Subsampling::yuv420);
        seconds += thread_cpu_seconds() - t0;
        c.out.display(
            "preset", std::string(p.name), q.spp, seconds, decoder.decode(bytes), relative_mse(full, c.out.reference()),
            false,
            std::to_string(bytes.size()) + (p.chroma_444 ? " bytes, 4:4:4" : " bytes, 4:2:0") + "; relMSE before JPEG");
    }
}

}  // namespace

std::vector<Measurement> sweep_knobs(const Scene& scene, Renderer& renderer, const QualityView& view,
                                     const RgbFloatImage& reference, const SweepOptions& options) {
    Recorder out(scene, view, reference);
    const Context c{scene, renderer, view, options, out};
    if (!options.presets_only) {
        spp_series(c);
        for (int spp : options.base_spp) path_knobs(c, spp);
        denoiser_series(c);
        jpeg_series(c);
        tile_series(c);
    }
    preset_rows(c);
    return std::move(out.rows);
}

}  // namespace mogao::quality
