// SPDX-License-Identifier: Apache-2.0
// mogao_procam_peer_bench: the bench calibration (procam_job.h) with our Gray-code decoder and with
// OpenCV's cv::structured_light::GrayCodePattern decoder (opencv_contrib; its white threshold 5 and
// the shadow mask white - black > 40 of its sample and of kamino410/procam-calibration), side by
// side on the real captures; both then take the same local homographies and the same calibration.
// Prints per decoder: decoded-pixel fraction, the two decoders' code agreement, stereo rms, the
// projector's intrinsics, and the leave-one-capture-out error of each held-out pose.
//
//   mogao_procam_peer_bench [--data DIR] [--write-docs]
//
// --write-docs replaces the text between the markers "<!-- procam-bench:begin -->" and
// "<!-- procam-bench:end -->" of docs/calibration.md. Exit 77 when the data is absent.
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <opencv2/structured_light.hpp>

#include "appliance/procam/capture_folder.h"
#include "appliance/procam/procam_calibration.h"
#include "appliance/procam/procam_job.h"

namespace {

using namespace mogao;
using namespace mogao::procam;

// OpenCV's decoder, as its structured_light sample and kamino410/procam-calibration call it.
DecodedPixels decode_peer(const std::vector<cv::Mat>& images, const GrayLayout& layout, const DecodeOptions& o) {
    cv::structured_light::GrayCodePattern::Params params;
    params.width = layout.projector.width;
    params.height = layout.projector.height;
    auto pattern = cv::structured_light::GrayCodePattern::create(params);
    pattern->setWhiteThreshold(static_cast<std::size_t>(o.min_bit_contrast));
    pattern->setBlackThreshold(static_cast<std::size_t>(o.shadow_threshold));
    const std::vector<cv::Mat> captured(images.begin(), images.begin() + layout.pattern_count());
    const cv::Mat& white = images[static_cast<std::size_t>(layout.white_index())];
    const cv::Mat& black = images[static_cast<std::size_t>(layout.black_index())];
    DecodedPixels d;
    d.projector = cv::Mat(white.size(), CV_32SC2, cv::Scalar(-1, -1));
    for (int y = 0; y < white.rows; ++y) {
        for (int x = 0; x < white.cols; ++x) {
            if (white.at<std::uint8_t>(y, x) - black.at<std::uint8_t>(y, x) <= o.shadow_threshold) continue;
            ++d.lit_pixels;
            cv::Point p;
            if (pattern->getProjPixel(captured, x, y, p)) continue;  // true: not decoded
            d.projector.at<cv::Vec2i>(y, x) = cv::Vec2i(p.x, p.y);
            ++d.decoded_pixels;
        }
    }
    return d;
}

struct Agreement {
    double both = 0.0;  // of the pixels either decoded, the fraction both decoded
    double same = 0.0;  // of the pixels both decoded, the fraction with the same code
};

Agreement agreement(const DecodedPixels& a, const DecodedPixels& b) {
    long either = 0, both = 0, same = 0;
    for (int y = 0; y < a.projector.rows; ++y) {
        for (int x = 0; x < a.projector.cols; ++x) {
            const bool da = a.decoded(x, y), db = b.decoded(x, y);
            either += (da || db) ? 1 : 0;
            if (!(da && db)) continue;
            ++both;
            same += a.projector.at<cv::Vec2i>(y, x) == b.projector.at<cv::Vec2i>(y, x) ? 1 : 0;
        }
    }
    return {either ? static_cast<double>(both) / static_cast<double>(either) : 0.0,
            both ? static_cast<double>(same) / static_cast<double>(both) : 0.0};
}

struct Side {
    std::string name;
    std::vector<BoardObservation> views;
    ProcamCalibration calibration;
    std::vector<HeldOutError> held_out;
};

std::string report(const std::vector<Side>& sides, const std::vector<Agreement>& agree, const ProcamJob& job) {
    std::ostringstream s;
    char line[512];
    s << "| decoder | decoded pixels (per capture) | stereo rms px | projector fx fy cx cy px | projector k1 k2 |\n"
         "|---|---|---|---|---|\n";
    for (const Side& side : sides) {
        std::string fractions;
        for (const BoardObservation& v : side.views) {
            std::snprintf(line, sizeof line, "%s%.1f %%", fractions.empty() ? "" : ", ", 100.0 * v.decoded_fraction);
            fractions += line;
        }
        const cv::Matx33d& k = side.calibration.projector.K;
        std::snprintf(line, sizeof line, "| %s | %s | %.3f | %.1f %.1f %.1f %.1f | %.4f %.4f |\n", side.name.c_str(),
                      fractions.c_str(), side.calibration.rms, k(0, 0), k(1, 1), k(0, 2), k(1, 2),
                      side.calibration.projector.dist[0], side.calibration.projector.dist[1]);
        s << line;
    }
    s << "\nCode agreement (pixels decoded by either: fraction both decoded; of those, fraction with the same "
         "projector pixel):";
    for (std::size_t i = 0; i < agree.size(); ++i) {
        std::snprintf(line, sizeof line, " %s %.1f %% / %.2f %%;", sides[0].views[i].name.c_str(),
                      100.0 * agree[i].both, 100.0 * agree[i].same);
        s << line;
    }
    s << "\n\nLeave one capture out (calibrated on the other three; projector px, predicted from the camera's "
         "board pose against the decoded corners), mean / p95:\n\n| held out | ours | peer | peer, OpenCV's default "
         "model |\n"
         "|---|---|---|---|\n";
    for (std::size_t i = 0; i < sides[0].held_out.size(); ++i) {
        s << "| " << sides[0].held_out[i].name;
        for (const Side& side : sides) {
            std::snprintf(line, sizeof line, " | %.3f / %.3f", side.held_out[i].mean_px, side.held_out[i].p95_px);
            s << line;
        }
        s << " |\n";
    }
    std::snprintf(line, sizeof line,
                  "\nSettings: shadow threshold %.0f, bit contrast %.0f grey levels; homography window %d px "
                  "half-width, RANSAC %.2f px; calibrateCamera flags camera %d, projector %d; stereo %s. The default "
                  "model: every coefficient free, intrinsics fixed in stereo, least-squares homographies.\n",
                  job.decode.shadow_threshold, job.decode.min_bit_contrast, job.homography.half_window_px,
                  job.homography.ransac_px, job.calibration.camera_flags, job.calibration.projector_flags,
                  job.calibration.refine_in_stereo ? "refined" : "intrinsics fixed");
    s << line;
    return s.str();
}

int write_docs(const std::string& text) {
    const std::string path = std::string(MOGAO_SOURCE_DIR) + "/docs/calibration.md";
    std::ifstream in(path);
    std::stringstream doc;
    doc << in.rdbuf();
    std::string all = doc.str();
    const std::string begin = "<!-- procam-bench:begin -->", end = "<!-- procam-bench:end -->";
    const auto b = all.find(begin), e = all.find(end);
    if (b == std::string::npos || e == std::string::npos || e < b) {
        std::cerr << path << ": the markers " << begin << " and " << end << " are missing\n";
        return 1;
    }
    all = all.substr(0, b + begin.size()) + "\n" + text + all.substr(e);
    std::ofstream(path) << all;
    std::cout << "written to " << path << "\n";
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Bench calibration: our Gray-code decoder against OpenCV's, on the real captures"};
    std::string data = MOGAO_PROCAM_DIR;
    bool docs = false;
    ProcamJob job;
    job.projector = ImageSize{1024, 768};
    job.board = BoardSpec{9, 7, 75.0};
    app.add_option("--data", data, "Folder with capture_0 .. capture_3");
    app.add_flag("--write-docs", docs, "Write the tables into docs/calibration.md");
    app.add_option("--shadow", job.decode.shadow_threshold, "Shadow threshold, white - black grey levels");
    app.add_option("--bit-contrast", job.decode.min_bit_contrast, "Least |pattern - inverse|, grey levels");
    app.add_option("--bit-fraction", job.decode.bit_contrast_fraction, "... or this fraction of white - black");
    app.add_option("--half-window-px", job.homography.half_window_px, "Homography window half-width, camera px");
    app.add_option("--ransac", job.homography.ransac_px, "RANSAC distance, projector px (0: least squares)");
    app.add_option("--projector-flags", job.calibration.projector_flags, "cv::calibrateCamera flags, projector");
    app.add_option("--camera-flags", job.calibration.camera_flags, "cv::calibrateCamera flags, camera");
    app.add_flag("!--fix-intrinsics", job.calibration.refine_in_stereo, "Fix the intrinsics in stereoCalibrate");
    CLI11_PARSE(app, argc, argv);
    for (int i = 0; i < 4; ++i) job.captures.push_back(std::filesystem::path(data) / ("capture_" + std::to_string(i)));
    if (!std::filesystem::is_directory(job.captures[0])) {
        std::cerr << "skipped: " << job.captures[0] << " is absent (../shared/data/structured-light)\n";
        return 77;
    }
    const GrayLayout layout = gray_layout(job.projector);
    std::vector<Side> sides{{"ours", {}, {}, {}},
                            {"OpenCV GrayCodePattern (peer)", {}, {}, {}},
                            {"peer, OpenCV's default model", {}, {}, {}}};
    // kamino410/procam-calibration's procedure: least-squares homographies, every distortion
    // coefficient free, intrinsics fixed in stereoCalibrate.
    HomographyOptions least_squares = job.homography;
    least_squares.ransac_px = 0.0;
    const CalibrationOptions opencv_default{0, 0, false};
    std::vector<Agreement> agree;
    ImageSize camera{};
    for (const auto& folder : job.captures) {
        const std::vector<cv::Mat> images = load_capture_folder(folder, layout);
        camera = ImageSize{images[0].cols, images[0].rows};
        const DecodedPixels ours = decode_gray(images, layout, job.decode);
        const DecodedPixels peer = decode_peer(images, layout, DecodeOptions{});  // its sample's 40 and 5
        agree.push_back(agreement(ours, peer));
        const cv::Mat& white = images[static_cast<std::size_t>(layout.white_index())];
        const std::string name = folder.filename().string();
        sides[0].views.push_back(observe_board(name, white, ours, job.board, job.homography));
        sides[1].views.push_back(observe_board(name, white, peer, job.board, job.homography));
        sides[2].views.push_back(observe_board(name, white, peer, job.board, least_squares));
    }
    for (std::size_t i = 0; i < sides.size(); ++i) {
        const CalibrationOptions& o = i < 2 ? job.calibration : opencv_default;
        sides[i].calibration = calibrate_procam(sides[i].views, camera, job.projector, o);
        sides[i].held_out = leave_one_out(sides[i].views, camera, job.projector, o);
    }
    const std::string text = report(sides, agree, job);
    std::cout << text;
    return docs ? write_docs(text) : 0;
}
