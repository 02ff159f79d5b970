// SPDX-License-Identifier: Apache-2.0
// The temporal accumulation's cost on the admin for a moving frame at the size the live tour serves
// (480x270: 960x540 at its resolution-scale floor), against the à-trous filter that follows it on
// the same frame (one level, as LiveOptions::blended_denoise_iterations; its luminance variance
// estimated spatially, or taken from the history's moments), and its per-pixel reprojection in float
// (renderfarm/trace/frame_projection.h) against camera.h's double-precision functions, all measured in this run.
//   mogao_bench_temporal [--width 480] [--height 270] [--frames 60] [--shading-one-in 4]
//                        [--write-docs docs/renderer.md]
// --write-docs FILE replaces the block between `<!-- generated:temporal -->` and `<!-- /generated -->`.
// The frames are analytic, so the bench needs no scene: a cylinder screen camera turning by 0.25
// degrees a frame inside a textured cylindrical wall 4 m around its eye (every pixel a surface, so
// every pixel is reprojected: the dearest case), radiance = albedo x a smooth light + noise.
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench/quality/bench_report.h"
#include "common/view_request.h"
#include "renderfarm/denoise/atrous_filter.h"
#include "renderfarm/denoise/temporal_accumulation.h"
#include "renderfarm/trace/camera.h"
#include "renderfarm/trace/frame_projection.h"

namespace {

using namespace mogao;
using Clock = std::chrono::steady_clock;
using bench::fmt;

struct Options {
    int width = 480;
    int height = 270;
    int frames = 60;
    int shading_one_in = 4;
};

CameraSetup camera_at(const Options& o, int frame) {
    ViewRequest r;
    r.size = {o.width, o.height};
    CylinderScreen screen;
    screen.radius_m = 3.0;
    screen.arc_deg = 150.0;
    screen.bottom_m = 0.8;
    screen.top_m = 2.3;
    r.camera = screen;
    r.pose.eye = {0.0, 1.6, 0.0};
    r.pose.yaw_deg = 0.25 * frame;
    return make_camera_setup(r, r.size);
}

// One frame of the wall x^2 + z^2 = kWall^2 around the eye: guides and radiance (sparse frames mark
// the pixels off their pattern kUnshadedRadiance, as the render ranks do).
constexpr double kWall = 4.0;
void make_frame(const CameraSetup& camera, int frame, int one_in, std::mt19937& rng, RgbFloatImage& radiance,
                GuideBuffers& guides) {
    std::normal_distribution<float> noise(0.0f, 0.05f);
    radiance = RgbFloatImage(camera.size);
    guides = GuideBuffers(camera.size);
    for (int y = 0; y < camera.size.height; ++y) {
        for (int x = 0; x < camera.size.width; ++x) {
            const Ray ray = generate_ray(camera, x + 0.5, y + 0.5);
            const Eigen::Vector2d d(ray.direction.x(), ray.direction.z());
            const Eigen::Vector2d e(ray.origin.x(), ray.origin.z());
            const double a = d.squaredNorm(), b = 2.0 * e.dot(d), c = e.squaredNorm() - kWall * kWall;
            const double t = (-b + std::sqrt(b * b - 4.0 * a * c)) / (2.0 * a) / ray.direction.norm();
            const Eigen::Vector3d p = ray.origin + t * ray.direction;
            const double theta = std::atan2(p.x(), -p.z());
            const float albedo = 0.2f + 0.6f * static_cast<float>((static_cast<int>(std::floor(theta * 60.0)) +
                                                                   static_cast<int>(std::floor(p.y() * 20.0))) &
                                                                  1);
            const Eigen::Vector3f normal = Eigen::Vector3d(-p.x(), 0.0, -p.z()).normalized().cast<float>();
            const float albedo_rgb[3] = {albedo, albedo, albedo};
            const std::size_t i = guides.pixel(x, y);
            guides.set_surface(i, albedo_rgb, normal.data(), static_cast<float>(t));
            const bool shaded = one_in == 1 || shades_pixel(one_in, frame % one_in, x, y);
            const float light = 0.5f + 0.3f * static_cast<float>(std::cos(2.0 * theta));
            float* out = radiance.at(x, y);
            for (int k = 0; k < 3; ++k)
                out[k] = shaded ? albedo * std::max(0.0f, light + noise(rng)) : kUnshadedRadiance;
        }
    }
}

double ms_since(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Nanoseconds per pixel to place every pixel's point at its depth and project it into the previous
// frame's camera: double (generate_ray, project_to_image), float a pixel at a time and float a row at
// a time (frame_projection.h).
std::string projection_table(const Options& o) {
    const CameraSetup now = camera_at(o, 1);
    const CameraSetup before = camera_at(o, 0);
    const double pixels = static_cast<double>(now.size.pixel_count());
    double sink = 0.0;
    constexpr int kReps = 20;
    const auto time_double = Clock::now();
    const CylinderColumns columns = make_cylinder_columns(now);
    for (int rep = 0; rep < kReps; ++rep) {
        for (int y = 0; y < now.size.height; ++y) {
            for (int x = 0; x < now.size.width; ++x) {
                const Ray ray = generate_column_ray(now, columns, x, y + 0.5);
                double px = 0.0, py = 0.0;
                if (project_to_image(before, ray.origin + kWall * ray.direction, px, py)) sink += px + py;
            }
        }
    }
    const double double_ns = ms_since(time_double) * 1e6 / (kReps * pixels);
    const auto time_float = Clock::now();
    const PixelCentreRays rays(now);
    const FrameProjection projection(before);
    for (int rep = 0; rep < kReps; ++rep) {
        for (int y = 0; y < now.size.height; ++y) {
            for (int x = 0; x < now.size.width; ++x) {
                float px = 0.0f, py = 0.0f;
                if (projection.project(rays.point(x, y, static_cast<float>(kWall)), px, py)) sink += px + py;
            }
        }
    }
    const double float_ns = ms_since(time_float) * 1e6 / (kReps * pixels);
    const auto w = static_cast<std::size_t>(now.size.width);
    std::vector<float> depth(w, static_cast<float>(kWall)), x(w), y(w), z(w), px(w), py(w);
    std::vector<std::uint8_t> ok(w);
    const auto time_row = Clock::now();
    for (int rep = 0; rep < kReps; ++rep) {
        for (int row = 0; row < now.size.height; ++row) {
            rays.points_row(row, depth.data(), now.size.width, x.data(), y.data(), z.data());
            projection.project_row(x.data(), y.data(), z.data(), now.size.width, px.data(), py.data(), ok.data());
            for (std::size_t i = 0; i < w; i += 97) sink += ok[i] != 0 ? px[i] + py[i] : 0.0;
        }
    }
    const double row_ns = ms_since(time_row) * 1e6 / (kReps * pixels);
    std::ostringstream md;
    md << "\n| reprojection of one pixel | ns | ratio |\n|---|--:|--:|\n"
       << "| double: generate_column_ray + project_to_image (camera.h) | " << fmt("%.1f", double_ns) << " | 1.00 |\n"
       << "| float, a pixel at a time: PixelCentreRays::point + FrameProjection::project | " << fmt("%.1f", float_ns)
       << " | " << fmt("%.2f", float_ns / double_ns) << " |\n"
       << "| float, a row at a time: points_row + project_row (frame_projection.h) | " << fmt("%.1f", row_ns) << " | "
       << fmt("%.2f", row_ns / double_ns) << " |\n\n"
       << "(checksum " << fmt("%.0f", sink) << ")\n";
    return md.str();
}

// The share of surface pixels whose luminance variance the history gives (>= 0; sky is 0 too, but
// these frames have none).
double known_share(const std::vector<float>& variance) {
    std::size_t known = 0;
    for (const float v : variance) known += v >= 0.0f ? 1 : 0;
    return variance.empty() ? 0.0 : static_cast<double>(known) / static_cast<double>(variance.size());
}

// Each frame blended, then filtered as a blended live frame is (one level): with the luminance
// variance estimated spatially at every pixel, and with the history's temporal variance (the spatial
// estimate only around the pixels without one), in alternating order.
std::string accumulation_table(const Options& o) {
    std::ostringstream md;
    md << "| frame, " << o.width << "x" << o.height
       << " | temporal accumulation ms | filter ms, spatial variance | filter ms, temporal variance | temporal / "
          "spatial variance | pixels with a temporal variance |\n|---|--:|--:|--:|--:|--:|\n";
    for (const int one_in : {1, o.shading_one_in}) {
        std::mt19937 rng(1);
        TemporalHistory history;
        AtrousDenoiser denoiser;
        AtrousParams filter;
        filter.threads = 0;
        filter.iterations = 1;  // LiveOptions::blended_denoise_iterations
        double temporal_ms = 0.0;
        double filter_ms = 0.0;
        double temporal_variance_ms = 0.0;
        double known = 0.0;
        int timed = 0;
        for (int frame = 0; frame < o.frames; ++frame) {
            const CameraSetup camera = camera_at(o, frame);
            RgbFloatImage radiance;
            GuideBuffers guides;
            make_frame(camera, frame, frame == 0 ? 1 : one_in, rng, radiance, guides);
            const auto start = Clock::now();
            const RgbFloatImage blended =
                history.accumulate(radiance, guides, camera, TemporalParams{}, nullptr, frame == 0 ? 1 : one_in);
            const double t = ms_since(start);
            double ms[2] = {0.0, 0.0};  // spatial, temporal variance
            for (int k = 0; k < 2; ++k) {
                const int which = (frame + k) % 2;
                const auto filter_start = Clock::now();
                RgbFloatImage out;
                if (Status st = denoiser.run(blended, guides, filter, out, nullptr,
                                             which == 1 ? &history.luminance_variance() : nullptr);
                    !st.ok())
                    throw std::runtime_error(st.error().message);
                ms[which] = ms_since(filter_start);
            }
            if (frame >= 2) {
                temporal_ms += t, filter_ms += ms[0], temporal_variance_ms += ms[1], ++timed;
                known += known_share(history.luminance_variance());
            }
        }
        md << "| " << (one_in == 1 ? "every pixel shaded" : "1 pixel in " + std::to_string(one_in) + " shaded") << " | "
           << fmt("%.2f", temporal_ms / timed) << " | " << fmt("%.2f", filter_ms / timed) << " | "
           << fmt("%.2f", temporal_variance_ms / timed) << " | " << fmt("%.2f", temporal_variance_ms / filter_ms)
           << " | " << fmt("%.2f", known / timed) << " |\n";
    }
    return md.str();
}

int run(int argc, char** argv) {
    Options o;
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string flag = argv[i];
        if (flag == "--write-docs") continue;  // bench::print_and_write_block reads it
        const int value = std::stoi(argv[i + 1]);
        if (flag == "--width") o.width = value;
        else if (flag == "--height") o.height = value;
        else if (flag == "--frames") o.frames = value;
        else if (flag == "--shading-one-in") o.shading_one_in = value;
        else throw std::invalid_argument("unknown flag " + flag);
    }
    if (o.width < 16 || o.height < 16 || o.frames < 4 || o.shading_one_in < 1 || o.shading_one_in > 16)
        throw std::invalid_argument("--width and --height >= 16, --frames >= 4, --shading-one-in in [1, 16]");
    const double load_start = bench::load_average();
    const std::string accumulation = accumulation_table(o);
    const std::string projection = projection_table(o);
    std::ostringstream md;
    md << "_Run " << bench::run_context() << ", load average " << fmt("%.2f", load_start) << " at start, "
       << fmt("%.2f", bench::load_average()) << " at end. Analytic frames (a cylinder camera turning 0.25° a frame "
       << "inside a textured wall: every pixel reprojected), " << o.frames << " frames, the first two not timed; each "
       << "frame filtered by one à-trous level on every core, as a blended live frame is (the share of pixels with a "
       << "temporal variance includes the history's first frames, when none has one). Regenerate: "
          "`build/bench/mogao_bench_temporal "
       << "--write-docs docs/renderer.md`._\n\n"
       << accumulation << projection;
    bench::print_and_write_block(argc, argv, "temporal", md.str());
    return 0;
}

}  // namespace

int main(int argc, char** argv) { return mogao::bench::run_main("mogao_bench_temporal", run, argc, argv); }
