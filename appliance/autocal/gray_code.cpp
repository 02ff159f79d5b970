// SPDX-License-Identifier: Apache-2.0
// Gray-code patterns and their decoding into projector <-> camera correspondences (autocal.h, 1).
#include "appliance/autocal/gray_code.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "appliance/autocal/camera_clipping.h"
#include "appliance/autocal/phase_shift.h"

namespace mogao::autocal {

int gray_code_bits(int extent) {
    int bits = 1;
    while ((1 << bits) < extent) ++bits;
    return bits;
}

cv::Mat1f gray_code_pattern(ImageSize size, bool rows, int bit, bool inverted) {
    const int n = gray_code_bits(rows ? size.height : size.width);
    if (bit < 0 || bit >= n)
        throw std::invalid_argument("gray_code_pattern: bit " + std::to_string(bit) + " outside 0.." +
                                    std::to_string(n - 1));
    cv::Mat1f img(size.height, size.width);
    for (int y = 0; y < size.height; ++y) {
        for (int x = 0; x < size.width; ++x) {
            const int i = rows ? y : x;
            const int gray = i ^ (i >> 1);
            const bool on = ((gray >> (n - 1 - bit)) & 1) != 0;
            img(y, x) = (on != inverted) ? 1.0f : 0.0f;
        }
    }
    return img;
}

namespace {

// Temporal noise of one camera image (camera units) from a pattern and its inverse: their light adds up to white
// plus black, so (on + off) - (white + black) over the lit pixels is the noise of four images (1.4826 MAD / 2).
double pair_noise(const cv::Mat1f& on, const cv::Mat1f& off, const cv::Mat1f& white_plus_black, const cv::Mat1i& code) {
    std::vector<float> dev;
    for (int y = 0; y < on.rows; ++y) {
        for (int x = 0; x < on.cols; ++x) {
            if (code(y, x) >= 0) dev.push_back(std::abs(on(y, x) + off(y, x) - white_plus_black(y, x)));
        }
    }
    return mad_sigma(dev) / 2.0;
}

// Decodes one axis: captures bits from the coarsest while the camera resolves them, at most
// options.max_gray_bits of them (0 = all), each pattern and inverse the mean of
// options.frames_per_pattern frames. Returns the number of bits used. Per camera pixel, `gray` gets the Gray-code
// prefix and `depth` the number of bits it resolved: a pixel stops at its first bit with |pattern - inverse| below half
// its contrast. For the reflected Gray code that bit changes at the middle of the pixel's block of `depth` bits, so the
// block's centre is where the pixel is (Inokuchi et al. 1984; the same property makes Gray code robust at stripe
// edges). Pixels below `shadow` contrast stay at -1.
// `noise`: set from the first pattern pair (pair_noise).
int decode_axis(PatternSource& source, int k, std::size_t projectors, ImageSize size, bool rows,
                const cv::Mat1f& contrast, const cv::Mat1f& white_plus_black, const AutocalOptions& options,
                cv::Mat1i& code, cv::Mat1i& depth, double& noise, int& captures) {
    const int all = gray_code_bits(rows ? size.height : size.width);
    const int n = options.max_gray_bits > 0 ? std::min(all, options.max_gray_bits) : all;
    const int frames = options.frames_per_pattern;
    cv::Mat1i gray(contrast.size(), 0);
    cv::Mat1b open(contrast.size(), 1);  // the pixel still takes bits
    int used = 0;
    for (int bit = 0; bit < n; ++bit) {
        std::vector<cv::Mat> signals(projectors);
        signals[static_cast<std::size_t>(k)] = gray_code_pattern(size, rows, bit, false);
        const cv::Mat1f on = show_averaged(source, signals, frames).clone();  // the source may reuse its buffer
        signals[static_cast<std::size_t>(k)] = gray_code_pattern(size, rows, bit, true);
        const cv::Mat1f off = show_averaged(source, signals, frames);
        captures += 2 * frames;
        if (bit == 0) noise = pair_noise(on, off, white_plus_black, code);
        long valid = 0;
        long resolved = 0;
        for (int y = 0; y < on.rows; ++y) {
            for (int x = 0; x < on.cols; ++x) {
                if (code(y, x) < 0) continue;
                ++valid;
                resolved += std::abs(on(y, x) - off(y, x)) > 0.5f * contrast(y, x);
            }
        }
        if (valid == 0 || static_cast<double>(resolved) < options.min_bit_fraction * static_cast<double>(valid)) break;
        for (int y = 0; y < on.rows; ++y) {
            for (int x = 0; x < on.cols; ++x) {
                if (code(y, x) < 0 || !open(y, x)) continue;
                const float d = on(y, x) - off(y, x);
                if (std::abs(d) < 0.5f * contrast(y, x)) {
                    open(y, x) = 0;
                    continue;
                }
                gray(y, x) = (gray(y, x) << 1) | (d > 0.0f ? 1 : 0);
                ++depth(y, x);
            }
        }
        ++used;
    }
    // Gray -> binary prefix.
    for (int y = 0; y < code.rows; ++y) {
        for (int x = 0; x < code.cols; ++x) {
            if (code(y, x) < 0) continue;
            int g = gray(y, x);
            int b = 0;
            for (; g != 0; g >>= 1) b ^= g;
            code(y, x) = b;
        }
    }
    return used;
}

}  // namespace

namespace {

// Image noise sigma of a nearly flat image (the all-black capture): the robust form of Immerkaer's
// estimator (Immerkaer 1996, "Fast noise variance estimation", CVIU 64(2)): the 3x3 mask
// [1 -2 1; -2 4 -2; 1 -2 1] cancels any locally planar signal and scales white noise by 6; the median
// absolute response (1.4826 MAD for a Gaussian) keeps the few edges of the image out.
double flat_image_noise(const cv::Mat1f& img) {
    if (img.rows < 3 || img.cols < 3) return 0.0;
    std::vector<float> r;
    r.reserve(static_cast<std::size_t>(img.rows - 2) * static_cast<std::size_t>(img.cols - 2));
    for (int y = 1; y + 1 < img.rows; ++y) {
        for (int x = 1; x + 1 < img.cols; ++x) {
            const float v = img(y - 1, x - 1) - 2 * img(y - 1, x) + img(y - 1, x + 1) - 2 * img(y, x - 1) +
                            4 * img(y, x) - 2 * img(y, x + 1) + img(y + 1, x - 1) - 2 * img(y + 1, x) +
                            img(y + 1, x + 1);
            r.push_back(std::abs(v));
        }
    }
    return mad_sigma(r) / 6.0;
}

// The projector's own contrast: the 99th percentile of white - black over the pixels above `floor` (0 when none are),
// a robust maximum that a few hot or clipped pixels do not set.
double high_contrast(const cv::Mat1f& contrast, double floor) {
    std::vector<float> lit;
    for (int y = 0; y < contrast.rows; ++y) {
        for (int x = 0; x < contrast.cols; ++x) {
            if (contrast(y, x) > floor) lit.push_back(contrast(y, x));
        }
    }
    if (lit.empty()) return 0.0;
    const auto at = lit.begin() + static_cast<long>(lit.size() * 99 / 100);
    std::nth_element(lit.begin(), at, lit.end());
    return *at;
}

// One axis's Gray decoding per camera pixel.
struct AxisCode {
    cv::Mat1i code;   // Gray-decoded block index, -1 = not lit
    cv::Mat1i depth;  // bits resolved
    int extent_bits = 0;
};

struct AxisPosition {
    cv::Mat1f position;  // projector image position, pixels
    cv::Mat1f sigma;     // its uncertainty, pixels
    cv::Mat1b refined;   // by the phase
};

AxisPosition gray_positions(const AxisCode& a) {
    AxisPosition p{cv::Mat1f(a.code.size(), 0.0f), cv::Mat1f(a.code.size(), 0.0f), cv::Mat1b(a.code.size(), 0)};
    for (int y = 0; y < a.code.rows; ++y) {
        for (int x = 0; x < a.code.cols; ++x) {
            if (a.code(y, x) < 0) continue;
            const int block = 1 << (a.extent_bits - a.depth(y, x));
            p.position(y, x) = static_cast<float>((a.code(y, x) + 0.5) * block);
            p.sigma(y, x) = static_cast<float>(block / std::sqrt(12.0));  // uniform over the block
        }
    }
    return p;
}

// One axis of phase-shifted sinusoids (phase_shift.h) for projector k: the unwrapped positions and
// their sigma replace the Gray-code block centres where the block is at most half a period and the
// modulation clears the noise. Returns the number of pixels refined.
int refine_by_phase(PatternSource& source, int k, std::size_t projectors, ImageSize size, bool rows, const AxisCode& a,
                    int resolved_bits, const cv::Mat1f& contrast, double image_noise, const AutocalOptions& o,
                    AxisPosition& p, int& captures) {
    const int n = o.phase_shifts;
    // At least 8 of the finest blocks the axis resolved: pixels that stopped up to two bits early still unwrap (a
    // noisy or blurred camera resolves fewer bits, and a longer period is also less attenuated by its blur).
    const double period = std::max(o.phase_period_px, 8.0 * (1 << (a.extent_bits - resolved_bits)));
    std::vector<cv::Mat1f> images;
    std::vector<cv::Mat> signals(projectors);
    for (int i = 0; i < n; ++i) {
        signals[static_cast<std::size_t>(k)] = phase_shift_pattern(size, rows, period, n, i, o.phase_gamma);
        images.push_back(show_averaged(source, signals, o.frames_per_pattern).clone());
        captures += o.frames_per_pattern;
    }
    // Images the camera clipped are left out pixel by pixel (phase_shift.h; a gain screen filmed bright).
    const PhaseImage phase = decode_phase(images, period, kCameraClipLevel);
    const cv::Mat1b lit(a.code >= 0);
    // The pattern pairs' temporal noise, or the phase images' own (for an even N, which also holds what the
    // sinusoid model misses, such as a wrong gamma's harmonics), the larger.
    const double noise = std::max(image_noise, phase_image_noise(images, lit, kCameraClipLevel));
    int refined = 0;
    for (int y = 0; y < a.code.rows; ++y) {
        for (int x = 0; x < a.code.cols; ++x) {
            if (a.code(y, x) < 0) continue;
            const int block = 1 << (a.extent_bits - a.depth(y, x));
            const double b = phase.modulation(y, x);
            const double sigma_phi_b = noise * phase.noise_gain(y, x);  // sigma_phi * b
            // Unwrapping needs the Gray position within P/2; a modulation below a quarter of the
            // contrast (a sinusoid washed out by blur or a bad gamma) or within 4 sigma of the noise
            // is not trusted.
            if (block > period / 2.0 || b < 0.25 * contrast(y, x) || !(b >= 4.0 * sigma_phi_b)) continue;
            p.position(y, x) = static_cast<float>(unwrap_position(p.position(y, x), phase.position(y, x), period));
            p.sigma(y, x) = static_cast<float>(
                std::max(o.phase_sigma_floor_px, period / (2.0 * std::numbers::pi) * sigma_phi_b / b));
            p.refined(y, x) = 1;
            ++refined;
        }
    }
    return refined;
}

}  // namespace

Correspondences decode_projector(PatternSource& source, int k, const std::vector<ImageSize>& projectors,
                                 const AutocalOptions& options) {
    const ImageSize size = projectors.at(static_cast<std::size_t>(k));
    std::vector<cv::Mat> signals(projectors.size());
    signals[static_cast<std::size_t>(k)] = cv::Mat1f(size.height, size.width, 1.0f);
    const cv::Mat1f white = show_averaged(source, signals, options.frames_per_pattern).clone();
    signals[static_cast<std::size_t>(k)] = cv::Mat();
    const cv::Mat1f black = show_averaged(source, signals, options.frames_per_pattern).clone();
    Correspondences out;
    out.captures = 2 * options.frames_per_pattern;
    cv::Mat1f contrast;
    cv::subtract(white, black, contrast);
    // Shadow mask: white - black over min_contrast and over the noise of that difference
    // (shadow_noise_sigmas times sqrt(2) sigma of one black image), so that a noisy camera's dark
    // pixels do not pass as lit.
    out.noise_sigma = flat_image_noise(black);
    out.shadow_threshold =
        std::max({options.min_contrast, options.shadow_noise_sigmas * std::sqrt(2.0) * out.noise_sigma,
                  options.shadow_relative * high_contrast(contrast, options.min_contrast)});
    AxisCode col{cv::Mat1i(contrast.size(), -1), cv::Mat1i(contrast.size(), 0), gray_code_bits(size.width)};
    for (int y = 0; y < contrast.rows; ++y) {
        for (int x = 0; x < contrast.cols; ++x) col.code(y, x) = contrast(y, x) > out.shadow_threshold ? 0 : -1;
    }
    AxisCode row{col.code.clone(), cv::Mat1i(contrast.size(), 0), gray_code_bits(size.height)};
    out.lit_pixels = cv::countNonZero(col.code == 0);
    cv::Mat1f white_plus_black;
    cv::add(white, black, white_plus_black);
    double col_noise = 0.0;
    double row_noise = 0.0;
    out.column_bits = decode_axis(source, k, projectors.size(), size, false, contrast, white_plus_black, options,
                                  col.code, col.depth, col_noise, out.captures);
    out.row_bits = decode_axis(source, k, projectors.size(), size, true, contrast, white_plus_black, options, row.code,
                               row.depth, row_noise, out.captures);
    if (out.column_bits < options.min_bits || out.row_bits < options.min_bits) return out;
    AxisPosition px = gray_positions(col);
    AxisPosition py = gray_positions(row);
    if (options.phase_shifts > 0) {
        out.phase_refined_columns = refine_by_phase(source, k, projectors.size(), size, false, col, out.column_bits,
                                                    contrast, col_noise, options, px, out.captures);
        out.phase_refined_rows = refine_by_phase(source, k, projectors.size(), size, true, row, out.row_bits, contrast,
                                                 row_noise, options, py, out.captures);
    }
    // One correspondence per decoded camera pixel whose every axis is refined by the phase or has
    // at least all but two of the resolved Gray bits: its centre <-> the projector position, with
    // that position's uncertainty. A regular stride keeps at most `max_correspondences`.
    const auto usable = [&](int y, int x) {
        return col.code(y, x) >= 0 && row.code(y, x) >= 0 &&
               (px.refined(y, x) || col.depth(y, x) >= std::max(1, out.column_bits - 2)) &&
               (py.refined(y, x) || row.depth(y, x) >= std::max(1, out.row_bits - 2));
    };
    long valid = 0;
    for (int y = 0; y < contrast.rows; ++y) {
        for (int x = 0; x < contrast.cols; ++x) valid += usable(y, x);
    }
    const long stride = std::max<long>(1, (valid + options.max_correspondences - 1) / options.max_correspondences);
    long seen = 0;
    for (int y = 0; y < contrast.rows; ++y) {
        for (int x = 0; x < contrast.cols; ++x) {
            if (!usable(y, x) || seen++ % stride != 0) continue;
            const double x_p = px.position(y, x);
            const double y_p = py.position(y, x);
            // Codes past the image are decoding errors.
            if (!(x_p >= 0.0 && x_p < size.width && y_p >= 0.0 && y_p < size.height)) continue;
            out.camera.emplace_back(x + 0.5, y + 0.5);
            out.projector.emplace_back(x_p, y_p);
            out.sigma.emplace_back(px.sigma(y, x), py.sigma(y, x));
        }
    }
    return out;
}

}  // namespace mogao::autocal
