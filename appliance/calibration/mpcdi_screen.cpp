// SPDX-License-Identifier: Apache-2.0
#include "appliance/calibration/mpcdi_screen.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "appliance/calibration/mpcdi_error.h"
#include "appliance/calibration/mpcdi_number.h"
#include "appliance/warp/calibration_validation.h"

namespace mogao {
namespace {

std::string size_text(ImageSize s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

WarpMap convert_warp(const MpcdiRegion& r, WarpSpace space, const std::string& who) {
    const PfmMap& m = r.warp.map;
    if (m.channels < 2) {
        throw MpcdiError(who + ": geometry warp has " + std::to_string(m.channels) +
                         " channel(s); a 2D warp needs r and g (PF)");
    }
    if (m.size.width > r.resolution.width || m.size.height > r.resolution.height) {
        throw MpcdiError(who + ": geometry warp grid " + size_text(m.size) + " is larger than the region resolution " +
                         size_text(r.resolution));
    }
    const bool relative = space == WarpSpace::region;
    WarpMap w;
    w.size = m.size;
    const auto count = static_cast<std::size_t>(m.size.pixel_count());
    w.uv.resize(count * 2);
    for (std::size_t i = 0; i < count; ++i) {
        const double s = m.values[i * static_cast<std::size_t>(m.channels)];
        const double t = m.values[i * static_cast<std::size_t>(m.channels) + 1];
        if (std::isnan(s) || std::isnan(t)) {
            w.uv[2 * i] = NAN;
            w.uv[2 * i + 1] = NAN;
            continue;
        }
        w.uv[2 * i] = static_cast<float>(relative ? r.x + r.xsize * s : s);
        w.uv[2 * i + 1] = static_cast<float>(relative ? r.y + r.ysize * t : t);
    }
    return w;
}

BlendMask convert_alpha(const MpcdiRegion& r, double assumed_gamma, const std::string& who,
                        std::vector<std::string>* notes) {
    const PngMap& a = r.alpha.map;
    if (a.size.width > r.resolution.width || a.size.height > r.resolution.height) {
        throw MpcdiError(who + ": alpha map " + size_text(a.size) + " is larger than the region resolution " +
                         size_text(r.resolution));
    }
    const double gamma = r.alpha.gamma_embedded > 0.0 ? r.alpha.gamma_embedded : assumed_gamma;
    const double max = std::ldexp(1.0, a.bit_depth) - 1.0;
    // One pow per code value instead of per pixel.
    std::vector<double> table(static_cast<std::size_t>(max) + 1);
    for (std::size_t k = 0; k < table.size(); ++k) table[k] = std::pow(static_cast<double>(k) / max, gamma);
    BlendMask b;
    b.size = a.size;
    const auto count = static_cast<std::size_t>(a.size.pixel_count());
    const auto ch = static_cast<std::size_t>(a.channels);
    b.weight.resize(count);
    bool channels_differ = false;
    for (std::size_t i = 0; i < count; ++i) {
        double sum = 0.0;
        for (std::size_t c = 0; c < ch; ++c) {
            sum += table[a.values[i * ch + c]];
            channels_differ = channels_differ || a.values[i * ch + c] != a.values[i * ch];
        }
        b.weight[i] = static_cast<float>(std::min(1.0, sum / static_cast<double>(ch)));
    }
    if (notes != nullptr && channels_differ) {
        notes->push_back("region \"" + r.id +
                         "\": RGB alpha map with different channels: blend weight = mean of the channels");
    }
    return b;
}

// Beta map code / (2^bits - 1) = offset in linear light, content units (BlackOffset); gray maps
// apply to all three channels.
BlackOffset convert_beta(const MpcdiRegion& r, const std::string& who) {
    BlackOffset b;
    if (!r.beta) return b;
    const PngMap& m = r.beta->map;
    if (m.size.width > r.resolution.width || m.size.height > r.resolution.height) {
        throw MpcdiError(who + ": beta map " + size_text(m.size) + " is larger than the region resolution " +
                         size_text(r.resolution));
    }
    const double max = std::ldexp(1.0, m.bit_depth) - 1.0;
    b.size = m.size;
    const auto count = static_cast<std::size_t>(m.size.pixel_count());
    const auto ch = static_cast<std::size_t>(m.channels);
    b.rgb.resize(count * 3);
    for (std::size_t i = 0; i < count; ++i) {
        for (std::size_t c = 0; c < 3; ++c) {
            b.rgb[i * 3 + c] = static_cast<float>(m.values[i * ch + (ch == 3 ? c : 0)] / max);
        }
    }
    return b;
}

ResponseCurve convert_response(const MpcdiResponseLut& lut) {
    ResponseCurve curve;
    const auto n = static_cast<std::size_t>(lut.map.size.width);
    for (std::size_t c = 0; c < 3; ++c) {
        curve.lut[c].resize(n);
        for (std::size_t k = 0; k < n; ++k) curve.lut[c][k] = lut.map.values[k * 3 + c];
    }
    return curve;
}

bool any_nonzero(const std::vector<float>& v) {
    return std::any_of(v.begin(), v.end(), [](float x) { return x != 0.0F; });
}

MpcdiBetaMap beta_map(const BlackOffset& beta) {
    MpcdiBetaMap m;
    m.map.size = beta.size;
    m.map.channels = 3;
    m.map.bit_depth = 16;
    m.map.values.resize(beta.rgb.size());
    for (std::size_t i = 0; i < beta.rgb.size(); ++i) {
        m.map.values[i] = static_cast<std::uint16_t>(std::clamp(std::round(65535.0 * beta.rgb[i]), 0.0, 65535.0));
    }
    return m;
}

MpcdiResponseLut response_lut(const ResponseCurve& curve, const std::string& id) {
    MpcdiResponseLut m;
    m.path = response_lut_entry(id);
    const std::size_t n = curve.lut[0].size();
    m.map.size = {static_cast<int>(n), 1};
    m.map.channels = 3;
    m.map.values.resize(n * 3);
    for (std::size_t k = 0; k < n; ++k) {
        for (std::size_t c = 0; c < 3; ++c) m.map.values[k * 3 + c] = curve.lut[c][k];
    }
    return m;
}

}  // namespace

ScreenCalibration to_screen_calibration(const MpcdiFile& file, const ScreenConversionOptions& options,
                                        std::vector<std::string>* notes) {
    if (file.profile != MpcdiProfile::two_d) {
        throw MpcdiError("to_screen_calibration: profile \"" + std::string(to_string(file.profile)) +
                         "\" is not supported (only 2d: its warps map projector pixels to content positions)");
    }
    if (options.buffer >= file.buffers.size()) {
        throw MpcdiError("to_screen_calibration: buffer index " + std::to_string(options.buffer) +
                         " but the file has " + std::to_string(file.buffers.size()) + " buffer(s)");
    }
    if (!(options.assumed_gamma > 0.0 && options.assumed_gamma <= 10.0)) {
        throw MpcdiError("to_screen_calibration: assumed_gamma must be in (0, 10]");
    }
    const MpcdiBuffer& buffer = file.buffers[options.buffer];
    ScreenCalibration screen;
    screen.content = buffer.resolution;
    for (const MpcdiRegion& r : buffer.regions) {
        const std::string who = "to_screen_calibration: region \"" + r.id + "\"";
        ProjectorCalibration p;
        p.id = r.id;
        p.output = r.resolution;
        p.warp = convert_warp(r, options.warp_space, who);
        p.blend = convert_alpha(r, options.assumed_gamma, who, notes);
        p.response = r.response ? convert_response(*r.response) : options.response;
        p.beta = convert_beta(r, who);
        if (notes != nullptr) {
            if (r.alpha.gamma_embedded == 0.0) {
                notes->push_back("region \"" + r.id + "\": gammaEmbedded 0, alpha decoded with gamma " +
                                 std::to_string(options.assumed_gamma));
            }
            if (r.distortion && any_nonzero(r.distortion->map.values)) {
                notes->push_back("region \"" + r.id + "\": non-zero distortion map ignored");
            }
        }
        screen.projectors.push_back(std::move(p));
    }
    try {
        validate_screen(screen);
    } catch (const std::invalid_argument& e) {
        throw MpcdiError(std::string("to_screen_calibration: the converted calibration is invalid: ") + e.what());
    }
    return screen;
}

double alpha_quantisation_bound(int bit_depth, double gamma) {
    // d/da a^gamma = gamma a^(gamma - 1): largest at a = 1 for gamma >= 1, unbounded near 0 below 1
    // (then the first step, 1/max, bounds it: (1/max)^gamma).
    const double max = std::ldexp(1.0, bit_depth) - 1.0;
    if (gamma >= 1.0) return gamma * 0.5 / max;
    return std::pow(1.0 / max, gamma);
}

MpcdiFile to_mpcdi(const ScreenCalibration& screen, const MpcdiExportOptions& options) {
    validate_screen(screen);
    if (options.alpha_bit_depth != 8 && options.alpha_bit_depth != 16) {
        throw std::invalid_argument("to_mpcdi: alpha_bit_depth " + std::to_string(options.alpha_bit_depth) +
                                    " must be 8 or 16");
    }
    if (!(options.alpha_gamma > 0.0 && options.alpha_gamma <= 10.0)) {
        throw std::invalid_argument("to_mpcdi: alpha_gamma must be in (0, 10]");
    }
    if (options.buffer_id.empty()) throw std::invalid_argument("to_mpcdi: buffer_id is empty");
    MpcdiFile file;
    file.profile = MpcdiProfile::two_d;
    file.version = "1.0";
    file.date = options.date;
    MpcdiBuffer buffer;
    buffer.id = options.buffer_id;
    buffer.resolution = screen.content;
    bool all_per_pixel = true;
    const double max = std::ldexp(1.0, options.alpha_bit_depth) - 1.0;
    for (const ProjectorCalibration& p : screen.projectors) {
        MpcdiRegion r;
        r.id = p.id;
        r.resolution = p.output;
        // Region = bounding box of the finite warp positions, within the buffer.
        double u0 = INFINITY, u1 = -INFINITY, v0 = INFINITY, v1 = -INFINITY;
        for (std::size_t i = 0; i < p.warp.uv.size(); i += 2) {
            if (std::isnan(p.warp.uv[i])) continue;
            u0 = std::min(u0, static_cast<double>(p.warp.uv[i]));
            u1 = std::max(u1, static_cast<double>(p.warp.uv[i]));
            v0 = std::min(v0, static_cast<double>(p.warp.uv[i + 1]));
            v1 = std::max(v1, static_cast<double>(p.warp.uv[i + 1]));
        }
        u0 = std::clamp(u0, 0.0, 1.0);
        u1 = std::clamp(u1, 0.0, 1.0);
        v0 = std::clamp(v0, 0.0, 1.0);
        v1 = std::clamp(v1, 0.0, 1.0);
        if (!(u1 - u0 > 1e-6)) u0 = 0.0, u1 = 1.0;  // empty or degenerate: the whole buffer
        if (!(v1 - v0 > 1e-6)) v0 = 0.0, v1 = 1.0;
        // Rounded to what "%g" prints, so mpcdi.xml reads like the reference files (x="0.370009");
        // the warp below is made relative to these rounded values, so nothing is lost.
        r.x = round_to_g(u0);
        r.y = round_to_g(v0);
        r.xsize = round_to_g(u1 - u0);
        r.ysize = round_to_g(v1 - v0);

        r.warp.interpolation = WarpInterpolation::linear;  // bilinear between samples (warp_sampling.h)
        r.warp.map.size = p.warp.size;
        r.warp.map.channels = 3;
        r.warp.map.values.resize(static_cast<std::size_t>(p.warp.size.pixel_count()) * 3);
        for (std::size_t i = 0, n = static_cast<std::size_t>(p.warp.size.pixel_count()); i < n; ++i) {
            const float u = p.warp.uv[2 * i];
            const float v = p.warp.uv[2 * i + 1];
            r.warp.map.values[3 * i] = std::isnan(u) ? NAN : static_cast<float>((u - r.x) / r.xsize);
            r.warp.map.values[3 * i + 1] = std::isnan(v) ? NAN : static_cast<float>((v - r.y) / r.ysize);
            r.warp.map.values[3 * i + 2] = 0.0F;
        }
        all_per_pixel =
            all_per_pixel && (p.warp.size.width > p.output.width / 10 || p.warp.size.height > p.output.height / 10);

        r.alpha.gamma_embedded = options.alpha_gamma;
        r.alpha.map.size = p.blend.size;
        r.alpha.map.channels = 1;
        r.alpha.map.bit_depth = options.alpha_bit_depth;
        r.alpha.map.values.resize(p.blend.weight.size());
        for (std::size_t i = 0; i < p.blend.weight.size(); ++i) {
            const double code =
                std::round(max * std::pow(static_cast<double>(p.blend.weight[i]), 1.0 / options.alpha_gamma));
            r.alpha.map.values[i] = static_cast<std::uint16_t>(std::clamp(code, 0.0, max));
        }
        if (!p.beta.rgb.empty()) r.beta = beta_map(p.beta);
        if (options.write_response) r.response = response_lut(p.response, r.id);
        buffer.regions.push_back(std::move(r));
    }
    file.level = all_per_pixel ? 3 : 1;
    file.buffers.push_back(std::move(buffer));
    return file;
}

}  // namespace mogao
