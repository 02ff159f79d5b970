// SPDX-License-Identifier: Apache-2.0
#include "bench/quality/image_metrics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/image_compare.h"

namespace mogao::quality {
namespace {

template <typename T>
void check_pair(const RgbImage<T>& x, const RgbImage<T>& reference, const char* what) {
    const auto n = static_cast<std::size_t>(reference.size.pixel_count()) * 3;
    if (x.size.width != reference.size.width || x.size.height != reference.size.height)
        throw std::invalid_argument(std::string(what) + ": image is " + std::to_string(x.size.width) + "x" +
                                    std::to_string(x.size.height) + ", reference " +
                                    std::to_string(reference.size.width) + "x" + std::to_string(reference.size.height));
    if (x.pixels.size() != n || reference.pixels.size() != n)
        throw std::invalid_argument(std::string(what) + ": pixel buffer length does not match the size");
}

// Luma plane of an sRGB8 image (BT.601 weights on the coded values).
std::vector<double> luma(const Rgb8Image& im) {
    std::vector<double> y(static_cast<std::size_t>(im.size.pixel_count()));
    for (std::size_t i = 0; i < y.size(); ++i)
        y[i] = 0.299 * im.pixels[3 * i] + 0.587 * im.pixels[3 * i + 1] + 0.114 * im.pixels[3 * i + 2];
    return y;
}

// 11-tap Gaussian, sigma 1.5, normalised; the 2-D window is its outer product (separable).
std::vector<double> gaussian_taps() {
    std::vector<double> w(11);
    double sum = 0;
    for (int i = 0; i < 11; ++i) sum += w[i] = std::exp(-double((i - 5) * (i - 5)) / (2 * 1.5 * 1.5));
    for (double& v : w) v /= sum;
    return w;
}

// 'Valid' separable Gaussian filter of a W x H plane: output (W - 10) x (H - 10).
std::vector<double> filter_valid(const std::vector<double>& in, int w, int h, const std::vector<double>& taps) {
    const int ow = w - 10, oh = h - 10;
    std::vector<double> rows(static_cast<std::size_t>(ow) * h), out(static_cast<std::size_t>(ow) * oh);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < ow; ++x) {
            double s = 0;
            for (int k = 0; k < 11; ++k) s += taps[k] * in[std::size_t(y) * w + x + k];
            rows[std::size_t(y) * ow + x] = s;
        }
    for (int y = 0; y < oh; ++y)
        for (int x = 0; x < ow; ++x) {
            double s = 0;
            for (int k = 0; k < 11; ++k) s += taps[k] * rows[std::size_t(y + k) * ow + x];
            out[std::size_t(y) * ow + x] = s;
        }
    return out;
}

}  // namespace

double relative_mse(const RgbFloatImage& x, const RgbFloatImage& reference, double epsilon) {
    check_pair(x, reference, "relative_mse");
    if (!(epsilon > 0)) throw std::invalid_argument("relative_mse: epsilon must be > 0");
    if (x.pixels.empty()) throw std::invalid_argument("relative_mse: empty image");
    double sum = 0;
    for (std::size_t i = 0; i < x.pixels.size(); ++i) {
        const double r = reference.pixels[i], d = double(x.pixels[i]) - r;
        sum += d * d / (r * r + epsilon);
    }
    return sum / double(x.pixels.size());
}

double display_psnr_db(const Rgb8Image& x, const Rgb8Image& reference) {
    check_pair(x, reference, "display_psnr_db");
    return psnr(x, reference);
}

double ssim_luminance(const Rgb8Image& x, const Rgb8Image& reference) {
    check_pair(x, reference, "ssim_luminance");
    const int w = x.size.width, h = x.size.height;
    if (w < 11 || h < 11)
        throw std::invalid_argument("ssim_luminance: image " + std::to_string(w) + "x" + std::to_string(h) +
                                    " is smaller than the 11x11 window");
    const std::vector<double> a = luma(x), b = luma(reference), taps = gaussian_taps();
    std::vector<double> aa(a.size()), bb(a.size()), ab(a.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        aa[i] = a[i] * a[i];
        bb[i] = b[i] * b[i];
        ab[i] = a[i] * b[i];
    }
    const auto mu_a = filter_valid(a, w, h, taps), mu_b = filter_valid(b, w, h, taps);
    const auto e_aa = filter_valid(aa, w, h, taps), e_bb = filter_valid(bb, w, h, taps),
               e_ab = filter_valid(ab, w, h, taps);
    const double c1 = (0.01 * 255) * (0.01 * 255), c2 = (0.03 * 255) * (0.03 * 255);
    double sum = 0;
    for (std::size_t i = 0; i < mu_a.size(); ++i) {
        const double va = e_aa[i] - mu_a[i] * mu_a[i], vb = e_bb[i] - mu_b[i] * mu_b[i];
        const double cov = e_ab[i] - mu_a[i] * mu_b[i];
        sum += ((2 * mu_a[i] * mu_b[i] + c1) * (2 * cov + c2)) /
               ((mu_a[i] * mu_a[i] + mu_b[i] * mu_b[i] + c1) * (va + vb + c2));
    }
    return sum / double(mu_a.size());
}

double relative_mse_db(double rel_mse) { return rel_mse > 0 ? -10.0 * std::log10(rel_mse) : INFINITY; }

RgbFloatImage resize_bilinear(const RgbFloatImage& in, ImageSize to) {
    if (in.size.width < 1 || in.size.height < 1 || to.width < 1 || to.height < 1)
        throw std::invalid_argument("resize_bilinear: empty image or target size");
    RgbFloatImage out(to);
    const auto coord = [](int o, int n_out, int n_in, int& i0, int& i1, double& f) {
        const double s = std::clamp((o + 0.5) * n_in / n_out - 0.5, 0.0, double(n_in - 1));
        i0 = int(s);
        i1 = std::min(i0 + 1, n_in - 1);
        f = s - i0;
    };
    for (int y = 0; y < to.height; ++y) {
        int y0, y1;
        double fy;
        coord(y, to.height, in.size.height, y0, y1, fy);
        for (int x = 0; x < to.width; ++x) {
            int x0, x1;
            double fx;
            coord(x, to.width, in.size.width, x0, x1, fx);
            for (int c = 0; c < 3; ++c) {
                const double top = (1 - fx) * in.at(x0, y0)[c] + fx * in.at(x1, y0)[c];
                const double bottom = (1 - fx) * in.at(x0, y1)[c] + fx * in.at(x1, y1)[c];
                out.at(x, y)[c] = float((1 - fy) * top + fy * bottom);
            }
        }
    }
    return out;
}

}  // namespace mogao::quality
