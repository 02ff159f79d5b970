// SPDX-License-Identifier: Apache-2.0
// The virtual rig filming the written pattern set (rig_film.h).
#include "kiosk/calibrate/rig_film.h"

#include <fstream>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "common/png_io.h"

namespace mogao::calibrate {
namespace {

namespace fs = std::filesystem;

nlohmann::json read_json(const fs::path& p) {
    std::ifstream f(p);
    if (!f) throw std::runtime_error(p.string() + ": cannot be read");
    return nlohmann::json::parse(f);
}

// A pattern file as the projector's signal, code / 255: CV_32FC1 when grey, else CV_32FC3.
cv::Mat signal_of(const Rgb8Image& png) {
    bool grey = true;
    for (std::size_t i = 0; i + 2 < png.pixels.size() && grey; i += 3)
        grey = png.pixels[i] == png.pixels[i + 1] && png.pixels[i] == png.pixels[i + 2];
    const std::uint8_t* p = png.pixels.data();
    if (grey) {
        cv::Mat1f s(png.size.height, png.size.width);
        for (int y = 0; y < s.rows; ++y) {
            for (int x = 0; x < s.cols; ++x, p += 3) s(y, x) = p[0] / 255.0f;
        }
        return s;
    }
    cv::Mat3f s(png.size.height, png.size.width);
    for (int y = 0; y < s.rows; ++y) {
        for (int x = 0; x < s.cols; ++x, p += 3) s(y, x) = cv::Vec3f(p[0], p[1], p[2]) / 255.0f;
    }
    return s;
}

Rgb8Image camera_codes(const cv::Mat1f& seen) {
    Rgb8Image out(ImageSize{seen.cols, seen.rows});
    for (int y = 0; y < seen.rows; ++y) {
        for (int x = 0; x < seen.cols; ++x) {
            std::uint8_t* px = out.at(x, y);
            px[0] = px[1] = px[2] = static_cast<std::uint8_t>(std::lround(255.0f * std::clamp(seen(y, x), 0.0f, 1.0f)));
        }
    }
    return out;
}

}  // namespace

int film_patterns(const fs::path& dir, const rig::VirtualRig& rig, std::uint64_t first_frame) {
    const nlohmann::json manifest = read_json(dir / "patterns.json");
    const nlohmann::json captures = read_json(dir / "captures.json").at("captures");
    if (manifest.at("projectors").size() != rig.projectors.size()) {
        throw std::runtime_error((dir / "patterns.json").string() + ": " +
                                 std::to_string(manifest["projectors"].size()) + " projectors, the rig has " +
                                 std::to_string(rig.projectors.size()));
    }
    const rig::CameraSimulator sim(rig);
    const std::size_t n = rig.projectors.size();
    std::vector<std::string> last_file(n);  // per projector: its file of the previous pattern, still decoded
    std::vector<cv::Mat> signals(n);
    int filmed = 0;
    for (const auto& p : manifest.at("patterns")) {
        for (std::size_t k = 0; k < n; ++k) {
            const std::string file =
                p.at("files").at(manifest["projectors"][k].at("id").get<std::string>()).get<std::string>();
            if (file != last_file[k]) signals[k] = signal_of(read_png(dir / file));
            last_file[k] = file;
        }
        const cv::Mat1f seen = sim.capture(signals, first_frame + p.at("order").get<std::uint64_t>());
        const fs::path out = dir / captures.at(p.at("id").get<std::string>()).get<std::string>();
        fs::create_directories(out.parent_path());
        write_png(out, camera_codes(seen));
        ++filmed;
    }
    return filmed;
}

}  // namespace mogao::calibrate
