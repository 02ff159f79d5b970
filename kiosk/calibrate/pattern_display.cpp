// SPDX-License-Identifier: Apache-2.0
// Calibration patterns on the appliance's outputs (pattern_display.h).
#include "kiosk/calibrate/pattern_display.h"

#include <poll.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mogao::calibrate {
namespace {

// IEC 61966-2-1 sRGB encoding of linear light x in [0, 1].
float srgb_encode(double x) {
    const double v = x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055;
    return static_cast<float>(std::clamp(v, 0.0, 1.0));
}

std::uint8_t code_of(float s) {
    const float c = std::isfinite(s) ? std::clamp(s, 0.0f, 1.0f) : 0.0f;
    return static_cast<std::uint8_t>(std::lround(255.0f * c));
}

}  // namespace

ProjectorCalibration identity_calibration(ImageSize output) {
    ProjectorCalibration pc;
    pc.id = "pattern";
    pc.output = output;
    pc.warp.size = output;
    pc.blend.size = output;
    const auto n = static_cast<std::size_t>(output.width) * static_cast<std::size_t>(output.height);
    pc.warp.uv.resize(2 * n);
    pc.blend.weight.assign(n, 1.0f);
    for (int y = 0; y < output.height; ++y) {
        for (int x = 0; x < output.width; ++x) {
            const std::size_t i =
                static_cast<std::size_t>(y) * static_cast<std::size_t>(output.width) + static_cast<std::size_t>(x);
            pc.warp.uv[2 * i] = static_cast<float>((x + 0.5) / output.width);
            pc.warp.uv[2 * i + 1] = static_cast<float>((y + 0.5) / output.height);
        }
    }
    for (auto& lut : pc.response.lut) {
        lut.resize(kIdentityLutEntries);
        for (int k = 0; k < kIdentityLutEntries; ++k) {
            lut[static_cast<std::size_t>(k)] = srgb_encode(static_cast<double>(k) / (kIdentityLutEntries - 1));
        }
    }
    return pc;
}

Rgb8Image pattern_content(const cv::Mat& signal, ImageSize size) {
    Rgb8Image out;
    out.size = size;
    out.pixels.assign(static_cast<std::size_t>(size.width) * static_cast<std::size_t>(size.height) * 3, 0);
    if (signal.empty()) return out;
    if (signal.cols != size.width || signal.rows != size.height ||
        (signal.type() != CV_32FC1 && signal.type() != CV_32FC3)) {
        throw std::invalid_argument("pattern: expected an empty, CV_32FC1 or CV_32FC3 image of " +
                                    std::to_string(size.width) + "x" + std::to_string(size.height) + ", got " +
                                    std::to_string(signal.cols) + "x" + std::to_string(signal.rows) + " of type " +
                                    std::to_string(signal.type()));
    }
    const bool grey = signal.type() == CV_32FC1;
    std::uint8_t* p = out.pixels.data();
    for (int y = 0; y < size.height; ++y) {
        const float* row = signal.ptr<float>(y);
        for (int x = 0; x < size.width; ++x, p += 3) {
            for (int c = 0; c < 3; ++c) p[c] = code_of(grey ? row[x] : row[3 * x + c]);
        }
    }
    return out;
}

Result<PatternDisplay> PatternDisplay::create(OutputBackend& backend, int flip_timeout_ms) {
    std::vector<std::size_t> index;
    for (const OutputInfo& info : backend.outputs()) {
        auto added = backend.renderer().add_projector(identity_calibration(info.size));
        if (!added) return with_context(added.error(), "pattern display: output " + info.name);
        index.push_back(added.value());
    }
    if (index.empty()) return make_error(EINVAL, "pattern display: the backend has no outputs");
    return PatternDisplay(backend, std::move(index), flip_timeout_ms);
}

Status PatternDisplay::show_outputs(const std::vector<cv::Mat>& per_output) {
    if (per_output.size() != output_count()) {
        return make_error(EINVAL, "pattern display: " + std::to_string(per_output.size()) + " patterns for " +
                                      std::to_string(output_count()) + " outputs");
    }
    std::vector<std::optional<Rgb8Image>> staged(output_count());
    for (std::size_t i = 0; i < output_count(); ++i) {
        const OutputInfo& info = output(i);
        Rgb8Image content;
        try {
            content = pattern_content(per_output[i], info.size);
        } catch (const std::invalid_argument& e) {
            return make_error(EINVAL, "output " + info.name + ": " + e.what());
        }
        if (i < shown_.size() && shown_[i] && shown_[i]->pixels == content.pixels) continue;  // still on screen
        if (auto s = backend_->begin_frame(i); !s) return with_context(s.error(), "output " + info.name);
        if (auto s = backend_->renderer().set_content(content); !s)
            return with_context(s.error(), "output " + info.name);
        if (auto s = backend_->renderer().draw(renderer_index_[i]); !s) {
            return with_context(s.error(), "output " + info.name);
        }
        if (auto s = backend_->stage(i); !s) return with_context(s.error(), "output " + info.name);
        staged[i] = std::move(content);
    }
    if (auto s = backend_->commit_round(); !s) return with_context(s.error(), "pattern display");
    shown_.resize(output_count());
    for (std::size_t i = 0; i < output_count(); ++i) {
        if (staged[i]) shown_[i] = std::move(staged[i]);
    }
    return wait_for_flips();
}

Status PatternDisplay::wait_for_flips() {
    using Clock = std::chrono::steady_clock;
    const auto deadline = Clock::now() + std::chrono::milliseconds(flip_timeout_ms_);
    for (;;) {
        std::size_t waiting = output_count();
        for (std::size_t i = 0; i < output_count(); ++i) {
            if (backend_->ready(i)) {
                --waiting;
            } else if (Clock::now() >= deadline) {
                return make_error(ETIMEDOUT, "output " + output(i).name +
                                                 ": the pattern's flip did not complete within " +
                                                 std::to_string(flip_timeout_ms_) + " ms");
            }
        }
        if (waiting == 0) return {};
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
        pollfd fd{backend_->event_fd(), POLLIN, 0};
        if (::poll(&fd, 1, static_cast<int>(std::max<long long>(1, left))) < 0 && errno != EINTR) {
            return make_error(errno, "pattern display: poll on the outputs' event fd");
        }
        if (auto r = backend_->dispatch_events(); !r) return with_context(r.error(), "pattern display");
    }
}

}  // namespace mogao::calibrate
