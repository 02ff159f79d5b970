// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/tag_detector.h"

#include <apriltag.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "common/unique_handle.h"
#include "drivers/camera/pixel_format.h"

namespace mogao {

struct TagDetector::Engine {
    explicit Engine(const std::string& family_name) : family(family_name) {}
    TagFamily family;
    // Declared after the family so it is destroyed first: apriltag_detector_destroy frees the
    // decode tables it hung on the family, reading the family to find them.
    UniquePtr<apriltag_detector, &apriltag_detector_destroy> detector{apriltag_detector_create()};
};

TagDetector::TagDetector(const DetectorSettings& settings)
    : settings_(settings), engine_(std::make_unique<Engine>(settings.family)) {
    validate(settings_);
    apriltag_detector* detector = engine_->detector.get();
    if (detector == nullptr) throw std::runtime_error("AprilTag could not allocate a detector");
    int max_hamming = settings_.max_hamming;
    if (settings_.cap_hamming_by_family)
        max_hamming = std::max(0, std::min(max_hamming, safe_max_hamming(engine_->family)));
    apriltag_detector_add_family_bits(detector, engine_->family.get(), max_hamming);
    detector->quad_decimate = settings_.decimation;
    detector->quad_sigma = settings_.blur_sigma;
    detector->refine_edges = settings_.refine_edges;
    detector->decode_sharpening = settings_.decode_sharpening;
    detector->nthreads = settings_.threads;
    detector->qtp.min_white_black_diff = settings_.min_white_black_diff;
    detector->qtp.max_line_fit_mse = settings_.max_line_fit_mse;
}

TagDetector::TagDetector(TagDetector&&) noexcept = default;
TagDetector& TagDetector::operator=(TagDetector&&) noexcept = default;
TagDetector::~TagDetector() = default;

void TagDetector::set_quad_search(float decimation, float blur_sigma) {
    DetectorSettings s = settings_;
    s.decimation = decimation;
    s.blur_sigma = blur_sigma;
    validate(s);
    settings_ = s;
    engine_->detector->quad_decimate = decimation;
    engine_->detector->quad_sigma = blur_sigma;
}

const TagFamily& TagDetector::family() const { return engine_->family; }

int safe_max_hamming(const TagFamily& family) {
    const apriltag_family* f = family.get();
    const double patterns = std::ldexp(1.0, static_cast<int>(f->nbits));
    double within = 0.0;  // bit patterns within h bits of one code: sum_{k<=h} C(nbits, k)
    double binomial = 1.0;
    int best = -1;
    for (int h = 0; h <= 2; ++h) {
        if (h > 0) binomial = binomial * static_cast<double>(static_cast<int>(f->nbits) - h + 1) / h;
        within += binomial;
        if (static_cast<double>(f->ncodes) * 4.0 * within / patterns > 0.01) break;
        best = h;
    }
    return best;
}

namespace {

// Adds the tags of a later pass that the earlier passes did not find: another id, or the same id
// more than half a tag side away (a second tag with that id).
void add_unseen(std::vector<TagDetection>& out, const std::vector<TagDetection>& later) {
    const std::size_t earlier = out.size();
    for (const auto& c : later) {
        const bool seen =
            std::any_of(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(earlier), [&](const TagDetection& d) {
                return d.id == c.id && (d.centre - c.centre).norm() < 0.5 * (d.corners[1] - d.corners[0]).norm();
            });
        if (!seen) out.push_back(c);
    }
}

// `image` up-sampled by `factor` with bicubic interpolation (DetectorSettings::upsample_pass_factor).
GrayImage upsampled(const GrayImage& image, int factor) {
    GrayImage up(image.width * factor, image.height * factor);
    const cv::Mat src(image.height, image.width, CV_8UC1, const_cast<std::uint8_t*>(image.pixels.data()));
    cv::Mat dst(up.height, up.width, CV_8UC1, up.pixels.data());
    cv::resize(src, dst, dst.size(), 0, 0, cv::INTER_CUBIC);
    return up;
}

}  // namespace

std::vector<TagDetection> TagDetector::detect(const GrayImage& image, Passes passes) {
    std::vector<TagDetection> out = detect_once(image);
    if (passes == Passes::single || settings_.decimation > 1.0f) return out;
    if (settings_.coarse_pass_decimation != 0.0f)
        add_unseen(out, detect_with_quad_search(image, settings_.coarse_pass_decimation, settings_.decode_sharpening));
    const auto pixels = static_cast<std::int64_t>(image.width) * image.height;
    const int factor = settings_.upsample_pass_factor;
    if (factor != 0 && pixels <= settings_.upsample_pass_max_pixels &&
        std::max(image.width, image.height) * factor <= kMaxCaptureDimension) {
        std::vector<TagDetection> small =
            detect_with_quad_search(upsampled(image, factor), 1.0f, settings_.upsample_pass_sharpening);
        for (auto& d : small) {
            for (auto& c : d.corners) c /= factor;
            d.centre /= factor;
        }
        add_unseen(out, small);
    }
    std::stable_sort(out.begin(), out.end(), [](const TagDetection& a, const TagDetection& b) { return a.id < b.id; });
    return out;
}

std::vector<TagDetection> TagDetector::detect_with_quad_search(const GrayImage& image, float decimation,
                                                               double decode_sharpening) {
    apriltag_detector* detector = engine_->detector.get();
    const auto restore = [&] {
        detector->quad_decimate = settings_.decimation;
        detector->quad_sigma = settings_.blur_sigma;
        detector->decode_sharpening = settings_.decode_sharpening;
    };
    detector->quad_decimate = decimation;
    detector->quad_sigma = 0.0f;
    detector->decode_sharpening = decode_sharpening;
    std::vector<TagDetection> found;
    try {
        found = detect_once(image);
    } catch (...) {
        restore();
        throw;
    }
    restore();
    return found;
}

std::vector<TagDetection> TagDetector::detect_once(const GrayImage& image) {
    if (!image.valid()) {
        throw std::invalid_argument("TagDetector::detect: image " + std::to_string(image.width) + "x" +
                                    std::to_string(image.height) + " with " + std::to_string(image.pixels.size()) +
                                    " pixels is not a valid grey image");
    }
    if (image.width > kMaxCaptureDimension || image.height > kMaxCaptureDimension) {
        throw std::invalid_argument("TagDetector::detect: image wider or taller than " +
                                    std::to_string(kMaxCaptureDimension));
    }
    // AprilTag reads the caller's buffer in place, except that with quad_decimate <= 1 and a
    // non-zero quad_sigma it blurs (or sharpens) that very buffer (apriltag.c, 3.3: quad_im ==
    // im_orig). Then it gets a copy, so `image` is never changed.
    const std::uint8_t* pixels = image.pixels.data();
    if (!(settings_.decimation > 1.0f) && settings_.blur_sigma != 0.0f) {
        scratch_ = image.pixels;
        pixels = scratch_.data();
    }
    image_u8_t view{image.width, image.height, image.width, const_cast<std::uint8_t*>(pixels)};
    zarray_t* found = apriltag_detector_detect(engine_->detector.get(), &view);
    std::vector<TagDetection> out;
    out.reserve(static_cast<std::size_t>(zarray_size(found)));
    for (int i = 0; i < zarray_size(found); ++i) {
        apriltag_detection_t* det = nullptr;
        zarray_get(found, i, &det);
        TagDetection d;
        d.id = det->id;
        d.hamming = det->hamming;
        d.decision_margin = det->decision_margin;
        for (int k = 0; k < 4; ++k) d.corners[static_cast<std::size_t>(k)] = {det->p[k][0], det->p[k][1]};
        d.centre = {det->c[0], det->c[1]};
        out.push_back(d);
    }
    apriltag_detections_destroy(found);
    std::stable_sort(out.begin(), out.end(), [](const TagDetection& a, const TagDetection& b) { return a.id < b.id; });
    return out;
}

}  // namespace mogao
