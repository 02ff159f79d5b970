// SPDX-License-Identifier: Apache-2.0
#include "appliance/calibration/calibration_cli.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <ostream>
#include <tuple>

#include "appliance/calibration/mpcdi_error.h"
#include "appliance/calibration/mpcdi_reader.h"
#include "appliance/calibration/mpcdi_screen.h"
#include "appliance/calibration/mpcdi_writer.h"
#include "appliance/warp/composite.h"
#include "appliance/warp/composite_check.h"
#include "appliance/warp/ideal_calibration.h"
#include "common/size_text.h"

namespace mogao {
namespace {

// Smooth test content for --check (gradient + sinusoidal checker, docs/calibration.md).
RgbFloatImage check_pattern(ImageSize size) {
    RgbFloatImage img(size);
    for (int y = 0; y < size.height; ++y) {
        for (int x = 0; x < size.width; ++x) {
            const double c =
                std::sin(2 * std::numbers::pi * (x + 0.5) / 96.0) * std::sin(2 * std::numbers::pi * (y + 0.5) / 96.0);
            float* p = img.at(x, y);
            p[0] = static_cast<float>(0.2 + 0.6 * (x + 0.5) / size.width + 0.15 * c);
            p[1] = static_cast<float>(0.2 + 0.6 * (y + 0.5) / size.height + 0.15 * c);
            p[2] = static_cast<float>(0.5 + 0.15 * c);
        }
    }
    return img;
}

int run_ideal(const MpcdiCommands& f, std::ostream& out) {
    const ScreenCalibration screen = make_ideal_calibration(f.params);
    MpcdiExportOptions options;
    options.alpha_bit_depth = f.alpha_bits;
    options.alpha_gamma = f.params.gamma;
    write_mpcdi(f.out, to_mpcdi(screen, options));
    out << "wrote " << f.out << ": " << f.params.projectors << " projectors " << f.params.output.width << "x"
        << f.params.output.height << ", overlap " << f.params.overlap << ", content " << f.params.content.width << "x"
        << f.params.content.height << ", alpha " << f.alpha_bits << "-bit gamma " << f.params.gamma << "\n";
    if (!f.check) return 0;
    // Check what was written, not what was meant: read the file back.
    ScreenConversionOptions conv;
    conv.response = make_gamma_response(f.params.gamma, f.params.response_entries);
    const ScreenCalibration back = to_screen_calibration(read_mpcdi(f.out), conv);
    const RgbFloatImage content = check_pattern(back.content);
    std::vector<RgbFloatImage> outputs;
    for (const auto& p : back.projectors) outputs.push_back(render_output(p, content));
    const RgbFloatImage lit = composite_on_screen(back, outputs);
    const ImageDifference d = compare_images(lit, content, {2, 2, back.content.width - 2, back.content.height - 2});
    const double tolerance = 1.0 / 255.0 + alpha_quantisation_bound(f.alpha_bits, f.params.gamma);
    out << "check: composite vs content (frame minus 2 px): max |error| " << d.max_abs << " at (" << d.max_x << ", "
        << d.max_y << "), mean " << d.mean_abs << ", tolerance " << tolerance
        << (d.max_abs < tolerance ? " OK" : " FAILED") << "\n";
    return d.max_abs < tolerance ? 0 : 1;
}

template <typename T>
void print_range(std::ostream& out, const std::vector<T>& values, int channels) {
    for (int c = 0; c < channels; ++c) {
        double lo = INFINITY, hi = -INFINITY;
        std::size_t nan = 0;
        for (std::size_t i = static_cast<std::size_t>(c); i < values.size(); i += static_cast<std::size_t>(channels)) {
            const auto v = static_cast<double>(values[i]);
            if (std::isnan(v)) {
                ++nan;
                continue;
            }
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
        out << (c == 0 ? " [" : ", [") << lo << ", " << hi << "]";
        if (nan > 0) out << " (" << nan << " NaN)";
    }
}

int run_info(const std::string& path, std::ostream& out) {
    std::vector<std::string> notes;
    const MpcdiFile f = read_mpcdi(path, &notes);
    out << path << ": MPCDI " << f.version << ", profile " << to_string(f.profile) << ", level " << f.level << ", date "
        << f.date << "\n";
    for (const MpcdiBuffer& b : f.buffers) {
        out << "buffer \"" << b.id << "\" " << b.resolution.width << "x" << b.resolution.height << ", "
            << b.regions.size() << " region(s)\n";
        for (const MpcdiRegion& r : b.regions) {
            out << "  region \"" << r.id << "\" " << r.resolution.width << "x" << r.resolution.height << " at x=" << r.x
                << " y=" << r.y << " size " << r.xsize << "x" << r.ysize << "\n";
            if (r.frustum) {
                const MpcdiFrustum& fr = *r.frustum;
                out << "    frustum yaw " << fr.yaw << " pitch " << fr.pitch << " roll " << fr.roll << ", left "
                    << fr.left_angle << " right " << fr.right_angle << " up " << fr.up_angle << " down "
                    << fr.down_angle << " (degrees)\n";
            }
            if (r.coordinate_frame) {
                const auto& c = *r.coordinate_frame;
                out << "    coordinateFrame pos (" << c.pos[0] << ", " << c.pos[1] << ", " << c.pos[2] << ")\n";
            }
            out << "    warp " << r.warp.path << ": " << r.warp.map.size.width << "x" << r.warp.map.size.height << " x"
                << r.warp.map.channels << ", unit " << to_string(r.warp.geometric_unit) << ", interpolation "
                << to_string(r.warp.interpolation) << ", origin " << to_string(r.warp.origin_of_3d_data) << ", ranges";
            print_range(out, r.warp.map.values, r.warp.map.channels);
            out << "\n    alpha " << r.alpha.path << ": " << r.alpha.map.size.width << "x" << r.alpha.map.size.height
                << " x" << r.alpha.map.channels << " " << r.alpha.map.bit_depth << "-bit, gammaEmbedded "
                << r.alpha.gamma_embedded << ", ranges";
            print_range(out, r.alpha.map.values, r.alpha.map.channels);
            out << "\n";
            if (r.beta) {
                out << "    beta " << r.beta->path << ": " << r.beta->map.size.width << "x" << r.beta->map.size.height
                    << " x" << r.beta->map.channels << ", ranges";
                print_range(out, r.beta->map.values, r.beta->map.channels);
                out << "\n";
            }
            if (r.distortion) {
                out << "    distortion " << r.distortion->path << ": " << r.distortion->map.size.width << "x"
                    << r.distortion->map.size.height << ", ranges";
                print_range(out, r.distortion->map.values, r.distortion->map.channels);
                out << "\n";
            }
        }
    }
    if (f.profile == MpcdiProfile::two_d) {
        const ScreenCalibration s = to_screen_calibration(f, {}, &notes);
        out << "as a screen calibration: content " << s.content.width << "x" << s.content.height << ", "
            << s.projectors.size() << " projector(s)\n";
    }
    for (const std::string& n : notes) out << "note: " << n << "\n";
    return 0;
}

}  // namespace

void add_mpcdi_commands(CLI::App& parent, MpcdiCommands& cmds) {
    CLI::App* ideal = parent.add_subcommand(
        "ideal", "Write the ideal calibration of N projectors side by side as a 2d-profile MPCDI file");
    ideal->add_option("--projectors", cmds.params.projectors, "Number of projectors")->check(CLI::Range(1, 64));
    ideal->add_option("--overlap", cmds.params.overlap, "Overlap, fraction of one projector's width, [0, 0.5)")
        ->check(CLI::Range(0.0, 0.4999999));
    ideal->add_option("--projector-size", cmds.projector_size, "Projector resolution WIDTHxHEIGHT");
    ideal->add_option("--content", cmds.content, "Content frame WIDTHxHEIGHT (the farm's frame)");
    ideal->add_option("--gamma", cmds.params.gamma, "Projector gamma, also the alpha maps' gammaEmbedded")
        ->check(CLI::Range(0.1, 10.0));
    ideal->add_option("--alpha-bits", cmds.alpha_bits, "Alpha map bits: 8 (reference-library compatible) or 16")
        ->check(CLI::IsMember({8, 16}));
    ideal->add_flag("--check", cmds.check, "Read the file back and run the composite check");
    ideal->add_option("--out", cmds.out, "Output .mpcdi file (written atomically)")->required();
    ideal->parse_complete_callback([&cmds] {
        for (const auto& [text, size, flag] :
             {std::tuple{&cmds.projector_size, &cmds.params.output, "--projector-size"},
              std::tuple{&cmds.content, &cmds.params.content, "--content"}}) {
            if (!parse_size(*text, *size, 1, 16384)) {
                throw CLI::ValidationError(flag, "'" + *text + "' is not WIDTHxHEIGHT with each side in 1..16384");
            }
        }
    });
    cmds.ideal = ideal;
    cmds.info = parent.add_subcommand("mpcdi-info", "Print what an MPCDI file holds");
    cmds.info->add_option("file", cmds.info_path, "MPCDI file")->required()->check(CLI::ExistingFile);
}

std::optional<int> run_mpcdi_commands(const MpcdiCommands& cmds, std::ostream& out, std::ostream& err) {
    const bool ideal = cmds.ideal->parsed();
    if (!ideal && !cmds.info->parsed()) return std::nullopt;
    try {
        return ideal ? run_ideal(cmds, out) : run_info(cmds.info_path, out);
    } catch (const std::exception& e) {  // MpcdiError, std::invalid_argument, std::bad_alloc
        err << "mogao-calibrate " << (ideal ? "ideal" : "mpcdi-info") << ": " << e.what() << "\n";
        return 1;
    }
}

}  // namespace mogao
