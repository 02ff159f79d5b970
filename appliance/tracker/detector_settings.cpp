// SPDX-License-Identifier: Apache-2.0
#include "appliance/tracker/detector_settings.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace mogao {
namespace {

template <typename T>
void check_range(const char* field, T value, T lo, T hi) {
    if (!(value >= lo && value <= hi)) {  // also catches NaN
        std::ostringstream msg;
        msg << "DetectorSettings." << field << " = " << value << " outside [" << lo << ", " << hi << "]";
        throw std::invalid_argument(msg.str());
    }
}

}  // namespace

void validate(const DetectorSettings& s) {
    check_range("decimation", s.decimation, 1.0f, 8.0f);
    check_range("blur_sigma", s.blur_sigma, -5.0f, 5.0f);
    check_range("min_white_black_diff", s.min_white_black_diff, 0, 255);
    check_range("decode_sharpening", s.decode_sharpening, 0.0, 1.0);
    check_range("max_hamming", s.max_hamming, 0, 2);
    check_range("threads", s.threads, 1, 64);
    check_range("max_line_fit_mse", s.max_line_fit_mse, 0.1f, 1000.0f);
    if (s.coarse_pass_decimation != 0.0f) check_range("coarse_pass_decimation", s.coarse_pass_decimation, 1.5f, 8.0f);
    if (s.upsample_pass_factor != 0) check_range("upsample_pass_factor", s.upsample_pass_factor, 2, 4);
    check_range("upsample_pass_sharpening", s.upsample_pass_sharpening, 0.0, 1.0);
    check_range("upsample_pass_max_pixels", s.upsample_pass_max_pixels, 0, 64 * 1024 * 1024);
}

}  // namespace mogao
