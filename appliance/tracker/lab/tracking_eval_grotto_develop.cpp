// SPDX-License-Identifier: Apache-2.0
// mogao_tracking_eval grotto-develop: the camera of the rendered grotto set. Each frame is the
// average of its ray-traced sub-frames in linear light (motion blur over the exposure), then the
// sensor's noise, the gain, sRGB encoding and JPEG (tracking_eval.h, GrottoDevelopOptions).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <stdexcept>

#include "appliance/tracker/lab/tracking_eval.h"
#include "appliance/tracker/lab/tracking_eval_grotto.h"
#include "common/file_io.h"
#include "common/image.h"
#include "common/jpeg_codec.h"
#include "common/png_io.h"
#include "common/srgb.h"

namespace mogao::eval {
namespace {

Rgb8Image develop_frame(const GrottoFrame& frame, const GrottoDevelopOptions& options) {
    std::array<double, 256> to_linear{};
    for (int v = 0; v < 256; ++v) to_linear[static_cast<std::size_t>(v)] = srgb_decode(v / 255.0);
    std::vector<double> sum;
    ImageSize size{};
    for (const auto& path : frame.subframes) {
        const Rgb8Image sub = read_ppm(path);
        if (sum.empty()) {
            size = sub.size;
            sum.assign(sub.pixels.size(), 0.0);
        } else if (!(sub.size == size)) {
            throw std::runtime_error(path.string() + ": sub-frame size differs from the frame's first sub-frame");
        }
        for (std::size_t i = 0; i < sum.size(); ++i) sum[i] += to_linear[sub.pixels[i]];
    }
    std::mt19937_64 rng(frame.noise_seed);
    std::normal_distribution<double> normal(0.0, 1.0);
    Rgb8Image out(size);
    const double n = static_cast<double>(frame.subframes.size());
    for (std::size_t i = 0; i < sum.size(); ++i) {
        const double signal = sum[i] / n;
        const double sigma = std::sqrt(options.shot * signal + options.read * options.read);
        const double l = std::clamp(frame.gain * (signal + sigma * normal(rng)), 0.0, 1.0);
        out.pixels[i] = static_cast<std::uint8_t>(std::lround(255.0 * srgb_encode(l)));
    }
    return out;
}

}  // namespace

int run_grotto_develop(const GrottoDevelopOptions& options) {
    const GrottoSet set = read_grotto_set(options.set);
    std::filesystem::create_directories(options.set / "frames");
    JpegEncoder encoder;
    for (const auto& frame : set.frames) {
        const Rgb8Image image = develop_frame(frame, options);
        const auto jpeg = encoder.encode(image, options.jpeg_quality, Subsampling::yuv420);
        write_file_atomically(set.developed(frame), jpeg);
    }
    std::printf("developed %zu frames into %s (shot %g, read %g, JPEG quality %d, 4:2:0)\n", set.frames.size(),
                (options.set / "frames").c_str(), options.shot, options.read, options.jpeg_quality);
    return 0;
}

}  // namespace mogao::eval
