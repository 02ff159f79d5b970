// SPDX-License-Identifier: Apache-2.0
// `mogao-calibrate procam` (procam_command.h).
#include "kiosk/calibrate/procam_command.h"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <stdexcept>
#include <utility>

#include "appliance/procam/procam_job.h"
#include "common/size_text.h"

namespace mogao::calibrate {

namespace {

bool parse_pair(const std::string& text, int& a, int& b, int lo, int hi) {
    ImageSize pair;
    if (!parse_size(text, pair, lo, hi)) return false;
    a = pair.width;
    b = pair.height;
    return true;
}

void print_result(const procam::ProcamJobResult& r, const std::filesystem::path& out) {
    const procam::ProcamCalibration& c = r.calibration;
    for (std::size_t i = 0; i < r.views.size(); ++i) {
        std::printf("%s: %.1f %% of the camera's pixels decoded, %zu corners; residual camera %.3f projector %.3f px\n",
                    r.views[i].name.c_str(), 100.0 * r.views[i].decoded_fraction, r.views[i].board.size(),
                    c.captures[i].camera_rms_px, c.captures[i].projector_rms_px);
    }
    const cv::Matx33d& k = c.projector.K;
    std::printf("projector fx %.1f fy %.1f cx %.1f cy %.1f px, k1 %.4f k2 %.4f; stereo rms %.3f px\n", k(0, 0), k(1, 1),
                k(0, 2), k(1, 2), c.projector.dist[0], c.projector.dist[1], c.rms);
    for (const procam::HeldOutError& h : r.held_out) {
        std::printf("held out %s: projector corners predicted within mean %.3f p95 %.3f max %.3f px\n", h.name.c_str(),
                    h.mean_px, h.p95_px, h.max_px);
    }
    std::printf("written to %s\n", out.c_str());
}

}  // namespace

void add_procam_command(CLI::App& parent, ProcamCommand& cmd) {
    cmd.app = parent.add_subcommand("procam",
                                    "Projector intrinsics on the bench from Gray-code captures of a board "
                                    "(docs/calibration.md)");
    cmd.app->add_option("--pose-images", cmd.images, "Capture folders (graycode_00.png ...), one per board pose")
        ->required()
        ->check(CLI::ExistingDirectory);
    cmd.app->add_option("--projector-size", cmd.projector, "Projector resolution WIDTHxHEIGHT")->required();
    // The same texts as `camera-intrinsics`' (one text per name, docs/cli.md).
    cmd.app->add_option("--board", cmd.board, "Chessboard inner corners, COLUMNSxROWS")->required();
    cmd.app->add_option("--square-mm", cmd.square_mm, "Chessboard square side, mm")
        ->required()
        ->check(CLI::Range(0.01, 10000.0));
    cmd.app->add_option("--out", cmd.out, "Calibration file (JSON) to write")->required();
    cmd.app->add_option("--half-window-px", cmd.window_px, "Local homography window half-width, camera pixels")
        ->check(CLI::Range(2, 200));
    cmd.app->add_flag("--projector-distortion", cmd.projector_distortion,
                      "Fit the projector's radial k1, k2 (needs many varied poses; default: a pinhole)");
}

int run_procam_command(const ProcamCommand& cmd) {
    procam::ProcamJob job;
    job.captures = cmd.images;
    if (!parse_pair(cmd.projector, job.projector.width, job.projector.height, 2, 16384)) {
        std::cerr << "mogao-calibrate procam: --projector-size " << cmd.projector
                  << ": must be WIDTHxHEIGHT, 2..16384\n";
        return 2;
    }
    if (!parse_pair(cmd.board, job.board.columns, job.board.rows, 2, 64)) {
        std::cerr << "mogao-calibrate procam: --board " << cmd.board << ": must be COLSxROWS inner corners, 2..64\n";
        return 2;
    }
    if (cmd.images.size() < 2) {
        std::cerr << "mogao-calibrate procam: --pose-images: at least 2 capture folders (board poses) are needed\n";
        return 2;
    }
    job.board.square_mm = cmd.square_mm;
    job.homography.half_window_px = cmd.window_px;
    if (cmd.projector_distortion) job.calibration.projector_flags = procam::CalibrationOptions::kRadialProjector;
    try {
        const procam::ProcamJobResult r = procam::run_procam_job(job);
        procam::write_procam_file(cmd.out, r.file);
        print_result(r, cmd.out);
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "mogao-calibrate procam: " << e.what() << "\n";
        return 1;
    }
}

autocal::BenchLens bench_lens_from_procam(const procam::Intrinsics& bench, std::string source) {
    // OpenCV's pixel centre is at integer coordinates, autocal's at +0.5.
    return {std::move(source),   bench.size,          bench.K(0, 0), bench.K(1, 1),
            bench.K(0, 2) + 0.5, bench.K(1, 2) + 0.5, bench.dist};
}

std::vector<std::optional<autocal::BenchLens>> bench_lenses_of(const rig::VirtualRig& rig, const std::string& file) {
    std::vector<std::optional<autocal::BenchLens>> lenses(rig.projectors.size());
    for (std::size_t k = 0; k < lenses.size(); ++k) {
        const std::filesystem::path& path = rig.projectors[k].procam;
        if (path.empty()) continue;
        try {
            lenses[k] = bench_lens_from_procam(procam::read_procam_projector(path), path.string());
        } catch (const std::exception& e) {
            throw std::runtime_error(file + ": projectors[" + std::to_string(k) + "].procam: " + e.what());
        }
    }
    return lenses;
}

}  // namespace mogao::calibrate
