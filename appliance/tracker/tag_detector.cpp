#include "appliance/tracker/tag_detector.h"

#include <apriltag.h>

#include <algorithm>
#include <stdexcept>
#include <string>

#include "drivers/camera/pixel_format.h"

namespace mogao {

void TagDetector::DetectorDeleter::operator()(apriltag_detector* d) const noexcept { apriltag_detector_destroy(d); }

TagDetector::TagDetector(const DetectorSettings& settings)
    : settings_(settings), family_(std::make_unique<TagFamily>(settings.family)) {
    validate(settings_);
    detector_.reset(apriltag_detector_create());
    if (!detector_) throw std::runtime_error("AprilTag could not allocate a detector");
    apriltag_detector_add_family_bits(detector_.get(), family_->get(), settings_.max_hamming);
    detector_->quad_decimate = settings_.decimation;
    detector_->quad_sigma = settings_.blur_sigma;
    detector_->refine_edges = settings_.refine_edges;
    detector_->decode_sharpening = settings_.decode_sharpening;
    detector_->nthreads = settings_.threads;
    detector_->qtp.min_white_black_diff = settings_.min_white_black_diff;
}

TagDetector::TagDetector(TagDetector&&) noexcept = default;
// Not defaulted: the old detector must be destroyed before the old family (destroying a detector
// frees the decode table it hung on its families), and member-wise assignment would free the
// family first.
TagDetector& TagDetector::operator=(TagDetector&& other) noexcept {
    if (this != &other) {
        detector_.reset();
        settings_ = std::move(other.settings_);
        scratch_ = std::move(other.scratch_);
        family_ = std::move(other.family_);
        detector_ = std::move(other.detector_);
    }
    return *this;
}
TagDetector::~TagDetector() = default;

std::vector<TagDetection> TagDetector::detect(const GrayImage& image) {
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
    zarray_t* found = apriltag_detector_detect(detector_.get(), &view);
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
